// The backend's configuration (ROBOT.json): workspace, table, motion parameters, the simulated
// arm's speed and the simulated world's objects. Every field has a default.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "arbci/robot/protocol.h"

namespace arbci::robot {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SimulatedObject {
  int id = 0;
  Vec3 position;  // the centre of its top face
  double height = 0.06;
  double radius = 0.03;  // of its footprint, for contact and grasping
};

struct RobotConfig {
  double speed_factor = 1.0;  // simulated seconds per real second
  double table_z = 0.0;
  Vec3 workspace_min{-0.7, 0.2, 0.0};
  Vec3 workspace_max{0.7, 1.1, 0.6};
  double approach_height = 0.10;  // above the target before descending
  double lift_height = 0.25;      // above the table after grasping
  double cartesian_speed = 0.30;  // m/s
  double descend_speed = 0.06;    // m/s, until contact
  double max_joint_speed = 1.2;   // rad/s
  double gripper_seconds = 0.5;
  Vec3 home{0.0, 0.45, 0.45};
  std::vector<SimulatedObject> objects;

  // Throws ConfigError naming the file and the field.
  static RobotConfig load(const std::filesystem::path& path);
  std::string toJson() const;
};

}  // namespace arbci::robot
