// The backend's configuration (ROBOT.json): workspace, table, motion parameters, the simulated
// arm's speed and the simulated world's objects. Each field's default, range and meaning is in
// robot::configSchema() (robot/settings.h); a file names only what differs.
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
  SimulatedObject();  // the schema's defaults
  SimulatedObject(int object_id, Vec3 top, double object_height, double object_radius)
      : SimulatedObject() {
    id = object_id;
    position = top;
    height = object_height;
    radius = object_radius;
  }
  int id;
  Vec3 position;  // the centre of its top face
  double height;
  double radius;    // of its footprint, for contact and grasping
  double mass;      // kg (the physics driver's)
  double friction;  // sliding friction coefficient (the physics driver's)
};

struct RobotConfig {
  RobotConfig();
  double speed_factor;  // simulated seconds per real second
  double table_z;
  Vec3 workspace_min;
  Vec3 workspace_max;
  double approach_height;  // above the target before descending
  double lift_height;      // above the table after grasping
  double cartesian_speed;  // m/s
  double descend_speed;    // m/s, until contact
  double max_joint_speed;  // rad/s
  double gripper_seconds;
  Vec3 home;
  // The mujoco driver: its arm's MJCF ("": the project's 6-axis arm), the grip it closes to and
  // the contact force that ends a descent.
  std::string model;
  double grip_force;     // N
  double contact_force;  // N
  std::vector<SimulatedObject> objects;

  // Throws ConfigError naming the file and the field.
  static RobotConfig load(const std::filesystem::path& path);
  std::string toJson() const;
};

}  // namespace arbci::robot
