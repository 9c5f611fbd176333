// Inverse kinematics on the physics model itself: the joint angles that put the tool point
// (site tcp) at a point with the tool pointing down and the fingers closing along the robot's x,
// by damped least squares on MuJoCo's site Jacobian. Works for 6 or more joints (a 7-axis arm's
// extra freedom stays near the starting posture).
#pragma once

#include <optional>
#include <vector>

#include "arbci/robot/protocol.h"
#include "mujoco/scene_model.h"

namespace arbci::robot::mujoco {

class ArmKinematics {
 public:
  ArmKinematics(const mjModel& model, const Contract& contract);

  // From `seed`, within the joints' limits; nothing when it does not converge.
  std::optional<std::vector<double>> solve(const Vec3& p, const std::vector<double>& seed,
                                           int iterations = 200) const;
  // From many fixed starts, the solution that keeps the arm's links highest above the table (an
  // elbow-up posture); for the first posture, when no seed is known.
  std::optional<std::vector<double>> solveAnywhere(const Vec3& p) const;
  Vec3 tool(const std::vector<double>& q) const;

 private:
  void place(const std::vector<double>& q) const;
  const mjModel& model_;
  const Contract& contract_;
  DataPtr data_;
};

}  // namespace arbci::robot::mujoco
