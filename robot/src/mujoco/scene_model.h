// The physics driver's world as one MuJoCo model: the arm's MJCF (the project's or a lab's) with
// the table and the configuration's objects added as bodies, and the names the driver needs from
// it (the contract, docs/robot.md) looked up once.
#pragma once

#include <mujoco/mujoco.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "arbci/robot/robot_config.h"

namespace arbci::robot::mujoco {

// The arm's MJCF text (its file's, or the embedded default arm's) with the table and `objects`
// added to its worldbody. Mesh and texture folders given relative to `folder` are made absolute.
// `what` names the model in errors (its file).
std::string composeScene(const std::string& arm_xml, const std::filesystem::path& folder,
                         const RobotConfig& config, const std::string& what);

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Compiles MJCF text; throws ConfigError with MuJoCo's message, prefixed by `what`.
ModelPtr compile(const std::string& xml, const std::string& what);

// The indices of what the driver reads and drives.
struct Contract {
  std::vector<int> joints;     // arm_joint_1.. in order
  std::vector<int> qpos, dof;  // their addresses
  std::vector<int> actuators;  // the position actuator of each
  int gripper = -1;            // actuator: ctrlrange low = open, high = closed
  int left_force = -1, right_force = -1, wrist_force = -1;  // sensor addresses (sensordata)
  int left_finger = -1, right_finger = -1;                  // the fingers' bodies
  int tcp = -1;                                             // site
  struct Object {
    int id = 0;
    int body = -1, geom = -1, qpos = -1;
    double half_height = 0.0;
  };
  std::vector<Object> objects;
};

// Throws ConfigError naming what `model` (from `what`) lacks.
Contract findContract(const mjModel& model, const RobotConfig& config, const std::string& what);

}  // namespace arbci::robot::mujoco
