// The physics driver: the arm, its gripper, the table and the objects in MuJoCo. The arm's
// joints follow position actuators (within their force limits, gravity compensated as an arm's
// controller does) along straight tool paths solved on the model's own kinematics; a descent ends
// when the wrist's force sensor feels contact, the gripper closes until its finger sensors read
// the grip force, and what the gripper holds is what physics holds: an object that slips or was
// never between the fingers is a failed grasp. Deterministic for a fixed sequence of steps.
#pragma once

#include <filesystem>
#include <memory>

#include "arbci/robot/robot_config.h"
#include "arbci/robot/robot_driver.h"

namespace arbci::robot {

class MujocoArm final : public RobotDriver {
 public:
  // The arm's model: config.model's file, else the project's 6-axis arm. Throws ConfigError
  // with the reason when the model cannot be loaded or lacks a part (docs/robot.md).
  explicit MujocoArm(const RobotConfig& config);
  ~MujocoArm() override;

  std::optional<Rejection> check(const DriverCommand& command) const override;
  void start(const DriverCommand& command) override;
  void stop() override;
  std::optional<DriverResult> step(double seconds) override;
  DriverStatus status() const override;
  std::vector<WorldObject> world() const override;

  // The physics step (seconds of robot time) and the number taken so far.
  double timestep() const;
  long steps() const;
  int armJoints() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The project's arms, by name ("arm6", "arm7"): their MJCF text.
std::string builtInArm(const std::string& name);

}  // namespace arbci::robot
