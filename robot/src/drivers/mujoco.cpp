// The physics driver (mujoco_arm.h): the arm, gripper, table and objects in MuJoCo.
#include "arbci/robot/mujoco_arm.h"
#include "arbci/robot/settings.h"

namespace arbci::robot {

DriverRegistry::Entry mujocoArmDriver() {
  return {"mujoco",
          "a 6-axis arm with a parallel gripper in the MuJoCo physics engine (the config's "
          "model: another MJCF); objects fall, slip and topple, grasps close to a force",
          {[](const RobotConfig& config) { return std::make_unique<MujocoArm>(config); }}};
}

}  // namespace arbci::robot
