// The default driver: a six-joint arm with the kinematics of a UR10 (Orocos KDL chain, joint
// limits, bounded joint speeds) and a gripper, in a simulated world of objects on a table.
// Motions are straight lines of the tool, pointing down, solved by inverse kinematics at every
// step; descents stop on contact with the table or an object.
#pragma once

#include <memory>

#include "arbci/robot/robot_config.h"
#include "arbci/robot/robot_driver.h"

namespace arbci::robot {

class SimulatedArm final : public RobotDriver {
 public:
  explicit SimulatedArm(const RobotConfig& config);
  ~SimulatedArm() override;

  std::optional<Rejection> check(const DriverCommand& command) const override;
  void start(const DriverCommand& command) override;
  void stop() override;
  std::optional<DriverResult> step(double seconds) override;
  DriverStatus status() const override;
  std::vector<WorldObject> world() const override;

  // True when the tool can reach `position` pointing down, within the joint limits.
  bool reachable(const Vec3& position) const;
  std::vector<double> joints() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arbci::robot
