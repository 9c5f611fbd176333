// The simulated arm (simulated_arm.h) as a driver: a 6-axis arm on Orocos KDL over the
// configuration's table and objects, at its speed factor.
#include "arbci/robot/settings.h"
#include "arbci/robot/simulated_arm.h"

namespace arbci::robot {

DriverRegistry::Entry simulatedArmDriver() {
  return {"simulated",
          "a simulated 6-axis arm (Orocos KDL) over the configuration's table and objects, "
          "speed_factor times faster than real",
          {[](const RobotConfig& config) { return std::make_unique<SimulatedArm>(config); }}};
}

}  // namespace arbci::robot
