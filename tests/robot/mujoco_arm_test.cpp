// The mujoco driver in process (no sockets): grasp, carry and put down by forces, a release above
// the table, an off-centre grasp, reproducibility and the 7-axis arm.
#include <gtest/gtest.h>

#include <cmath>

#include "arbci/robot/mujoco_arm.h"

namespace arbci::robot {
namespace {

// Two objects as the default session's: 7 cm square, 6 cm tall.
RobotConfig twoObjects(const std::string& model = "") {
  RobotConfig c;
  c.model = model;
  c.objects = {{10, {-0.09, 0.42, 0.06}, 0.06, 0.035}, {20, {0.09, 0.42, 0.06}, 0.06, 0.035}};
  return c;
}

DriverResult runToEnd(MujocoArm& arm, const DriverCommand& command, double limit_s = 60.0) {
  EXPECT_FALSE(arm.check(command)) << arm.check(command)->text;
  arm.start(command);
  for (double t = 0.0; t < limit_s; t += 0.05) {
    if (auto result = arm.step(0.05)) return *result;
  }
  ADD_FAILURE() << "the command did not end within " << limit_s << " s of robot time";
  return {Outcome::Failed, "timeout"};
}

WorldObject objectNamed(const MujocoArm& arm, int id) {
  for (const WorldObject& o : arm.world()) {
    if (o.id == id) return o;
  }
  ADD_FAILURE() << "no object " << id;
  return {};
}

TEST(MujocoArm, GraspsCarriesAndPutsDownWhereAsked) {
  MujocoArm arm(twoObjects());
  const DriverResult grasp = runToEnd(arm, {MessageType::Grasp, {-0.09, 0.42, 0.06}});
  EXPECT_EQ(grasp.outcome, Outcome::Success) << grasp.text;
  EXPECT_EQ(arm.status().holding, 10);
  EXPECT_GT(objectNamed(arm, 10).position.z, 0.2);  // lifted with the tool
  const DriverResult drop = runToEnd(arm, {MessageType::Drop, {0.1, 0.66, 0.0}});
  EXPECT_EQ(drop.outcome, Outcome::Success) << drop.text;
  EXPECT_EQ(arm.status().holding, -1);
  const WorldObject placed = objectNamed(arm, 10);
  EXPECT_NEAR(placed.position.x, 0.1, 0.01);
  EXPECT_NEAR(placed.position.y, 0.66, 0.01);
  EXPECT_NEAR(placed.position.z, 0.06, 0.002);  // resting on the table, upright
  const DriverResult home = runToEnd(arm, {MessageType::Home, {}});
  EXPECT_EQ(home.outcome, Outcome::Success) << home.text;
}

}  // namespace
}  // namespace arbci::robot
