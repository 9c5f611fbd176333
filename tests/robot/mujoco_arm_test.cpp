// The mujoco driver in process (no sockets): grasp, carry and put down by forces, a release above
// the table, an off-centre grasp, reproducibility, the stop, the 7-axis arm and a model that lacks
// a part of the contract.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

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

TEST(MujocoArm, AnObjectReleasedAboveTheTableFallsAndRestsOnIt) {
  MujocoArm arm(twoObjects());
  ASSERT_EQ(runToEnd(arm, {MessageType::Grasp, {-0.09, 0.42, 0.06}}).outcome, Outcome::Success);
  // Let go with its base 0.2 m above the table.
  const DriverResult drop = runToEnd(arm, {MessageType::Drop, {0.0, 0.66, 0.2}});
  EXPECT_EQ(drop.outcome, Outcome::Success) << drop.text;
  const WorldObject o = objectNamed(arm, 10);
  EXPECT_FALSE(o.held);
  // Resting on the table, upright or not: its top face's centre at its height when upright, at
  // half its width when on its side.
  const double upright =
      1 - 2 * (o.orientation[1] * o.orientation[1] + o.orientation[2] * o.orientation[2]);
  if (upright > 0.99)
    EXPECT_NEAR(o.position.z, 0.06, 0.002);
  else
    EXPECT_NEAR(o.position.z, 0.035, 0.002);
  // It fell, so did not land farther than a few centimetres from under the release.
  EXPECT_LT(std::hypot(o.position.x - 0.0, o.position.y - 0.66), 0.05);
}

// Off the object's centre by 60 % of its half-width: along the fingers' closing direction a finger
// lands on its top; across it the fingers close on its edge. Either way the verdict is what
// physics did: success only with the object lifted, else a failed grasp and the object on the
// table.
TEST(MujocoArm, AnOffCentreGraspSucceedsOnlyWhenTheObjectIsLifted) {
  for (const Vec3& offset :
       {Vec3{0.021, 0, 0}, Vec3{-0.021, 0, 0}, Vec3{0, 0.021, 0}, Vec3{0, -0.021, 0}}) {
    MujocoArm arm(twoObjects());
    const DriverResult grasp =
        runToEnd(arm, {MessageType::Grasp, {-0.09 + offset.x, 0.42 + offset.y, 0.06}});
    const WorldObject o = objectNamed(arm, 10);
    if (grasp.outcome == Outcome::Success) {
      EXPECT_EQ(arm.status().holding, 10);
      EXPECT_GT(o.position.z, 0.15)
          << "held but not lifted, offset " << offset.x << ", " << offset.y;
    } else {
      EXPECT_EQ(arm.status().holding, -1);
      EXPECT_LT(o.position.z, 0.07) << grasp.text;
      EXPECT_FALSE(grasp.text.empty());
    }
  }
}

TEST(MujocoArm, AGraspOverNothingFails) {
  MujocoArm arm(twoObjects());
  const DriverResult grasp = runToEnd(arm, {MessageType::Grasp, {0.0, 0.42, 0.06}});
  EXPECT_EQ(grasp.outcome, Outcome::Failed);
  EXPECT_NE(grasp.text.find("closed on nothing"), std::string::npos) << grasp.text;
  EXPECT_EQ(arm.status().holding, -1);
  // Nothing to put down.
  const auto refused = arm.check({MessageType::Drop, {0.0, 0.66, 0.0}});
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->reason, RejectReason::InvalidState);
}

TEST(MujocoArm, APointBeyondTheArmsReachIsRefused) {
  MujocoArm arm(twoObjects());
  const auto refused = arm.check({MessageType::Grasp, {0.0, 0.99, 0.06}});
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->reason, RejectReason::Unreachable);
}

// The same steps give the same world, to the bit.
TEST(MujocoArm, TheSameStepsGiveTheSameWorld) {
  auto run = [] {
    MujocoArm arm(twoObjects());
    arm.start({MessageType::Grasp, {-0.09, 0.42, 0.06}});
    for (int i = 0; i < 200; ++i) arm.step(0.0371);  // steps that do not divide the timestep
    arm.start({MessageType::Drop, {0.1, 0.7, 0.15}});
    for (int i = 0; i < 200; ++i) arm.step(0.0371);
    return arm.world();
  };
  const auto a = run(), b = run();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].position.x, b[i].position.x);
    EXPECT_EQ(a[i].position.y, b[i].position.y);
    EXPECT_EQ(a[i].position.z, b[i].position.z);
    EXPECT_EQ(a[i].orientation, b[i].orientation);
  }
}

TEST(MujocoArm, AStopHoldsTheArmWhereItIs) {
  MujocoArm arm(twoObjects());
  arm.start({MessageType::Grasp, {-0.09, 0.42, 0.06}});
  for (int i = 0; i < 10; ++i) arm.step(0.05);
  arm.stop();
  const Vec3 at = arm.status().tool;
  EXPECT_EQ(arm.status().state, RobotState::Stopped);
  EXPECT_FALSE(arm.step(1.0));  // a stopped arm does not move on
  EXPECT_EQ(arm.status().tool.x, at.x);
  EXPECT_EQ(arm.status().tool.z, at.z);
  // A new command starts from there.
  const DriverResult home = runToEnd(arm, {MessageType::Home, {}});
  EXPECT_EQ(home.outcome, Outcome::Success) << home.text;
}

// The default session's table: four objects in a row, the grid of 3 x 3 cells of 9 cm around
// (0, 0.66) (session/settings_schema.cpp's world).
RobotConfig defaultTable() {
  RobotConfig c;
  for (int k = 0; k < 4; ++k)
    c.objects.push_back({10 * (k + 1), {-0.27 + 0.18 * k, 0.42, 0.06}, 0.06, 0.035});
  return c;
}

// A sweep of the default grid: the object put down on every cell and grasped from it again, the
// arm home between, every step accepted and carried out.
TEST(MujocoArm, EveryCellOfTheDefaultGridIsPutDownOnAndGraspedFromAgain) {
  MujocoArm arm(defaultTable());
  for (int row = 1; row <= 3; ++row) {
    for (int column = 1; column <= 3; ++column) {
      SCOPED_TRACE("cell " + std::to_string(row) + "," + std::to_string(column));
      const Vec3 cell{(column - 2) * 0.09, 0.66 + (2 - row) * 0.09, 0.0};
      const Vec3 at = objectNamed(arm, 20).position;
      const DriverResult grasp = runToEnd(arm, {MessageType::Grasp, at});
      ASSERT_EQ(grasp.outcome, Outcome::Success) << grasp.text;
      const DriverResult drop = runToEnd(arm, {MessageType::Drop, cell});
      ASSERT_EQ(drop.outcome, Outcome::Success) << drop.text;
      ASSERT_EQ(runToEnd(arm, {MessageType::Home, {}}).outcome, Outcome::Success);
      EXPECT_NEAR(objectNamed(arm, 20).position.x, cell.x, 0.01);
      EXPECT_NEAR(objectNamed(arm, 20).position.y, cell.y, 0.01);
    }
  }
  // And from the last cell once more.
  EXPECT_EQ(runToEnd(arm, {MessageType::Grasp, objectNamed(arm, 20).position}).outcome,
            Outcome::Success);
}

// What the arm accepts, it can do: at the edge of its reach (where the arm once accepted grasps
// whose travel it could not follow), every accepted grasp ends without a path fault, every
// refused one says which point of its path no joint motion reaches.
TEST(MujocoArm, AtTheEdgeOfItsReachItAcceptsOnlyPathsItCanFollow) {
  int accepted = 0, refused = 0;
  for (const double x : {0.0, 0.25}) {
    for (const double y : {0.70, 0.75, 0.80, 0.85, 0.90}) {
      MujocoArm arm(twoObjects());
      const DriverCommand grasp{MessageType::Grasp, {x, y, 0.06}};
      if (const auto no = arm.check(grasp)) {
        ++refused;
        EXPECT_EQ(no->reason, RejectReason::Unreachable) << no->text;
        EXPECT_NE(no->text.find("its path passes"), std::string::npos) << no->text;
        continue;
      }
      ++accepted;
      arm.start(grasp);
      std::optional<DriverResult> result;
      for (double t = 0.0; t < 60.0 && !result; t += 0.05) result = arm.step(0.05);
      ASSERT_TRUE(result);
      EXPECT_EQ(result->text.find("no joint motion"), std::string::npos)
          << x << ", " << y << ": " << result->text;
      EXPECT_NE(arm.status().state, RobotState::Fault) << x << ", " << y;
    }
  }
  EXPECT_GT(accepted, 0);
  EXPECT_GT(refused, 0);
}

TEST(MujocoArm, TheSevenAxisArmGraspsAndPutsDown) {
  MujocoArm arm(twoObjects("arm7"));
  EXPECT_EQ(arm.armJoints(), 7);
  ASSERT_EQ(runToEnd(arm, {MessageType::Grasp, {0.09, 0.42, 0.06}}).outcome, Outcome::Success);
  ASSERT_EQ(runToEnd(arm, {MessageType::Drop, {-0.09, 0.75, 0.0}}).outcome, Outcome::Success);
  const WorldObject placed = objectNamed(arm, 20);
  EXPECT_NEAR(placed.position.x, -0.09, 0.01);
  EXPECT_NEAR(placed.position.y, 0.75, 0.01);
}

TEST(MujocoArm, ALabsModelFileLoadsAndOneWithoutThePartsItNeedsIsRefusedByName) {
  const auto folder = std::filesystem::temp_directory_path() / "arbci_mujoco_model_test";
  std::filesystem::create_directories(folder);
  std::string arm = builtInArm("arm6");
  // A lab's file that keeps the contract loads.
  std::ofstream(folder / "arm.xml") << arm;
  EXPECT_EQ(MujocoArm(twoObjects((folder / "arm.xml").string())).armJoints(), 6);
  const std::string sensor = "<force name=\"wrist_force\" site=\"wrist\"/>";
  arm.erase(arm.find(sensor), sensor.size());
  std::ofstream(folder / "arm.xml") << arm;
  RobotConfig c = twoObjects((folder / "arm.xml").string());
  try {
    MujocoArm refused(c);
    ADD_FAILURE() << "a model without a wrist force sensor was loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("wrist_force"), std::string::npos) << e.what();
  }
  std::ofstream(folder / "arm.xml") << "<mujoco><worldbody><body></mujoco>";
  try {
    MujocoArm refused(c);
    ADD_FAILURE() << "a broken file was loaded";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("arm.xml"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace arbci::robot
