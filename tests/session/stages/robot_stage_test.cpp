// The robot stage on hand-built records against a real backend on 127.0.0.1 (a simulated arm on
// its own thread, stepped on the session's clock or on the wall clock): the trial's grasp and
// put-down, noted on the record for the paradigm (outcome, step finished, placement, put-down
// ended), the experimenter's stop and reset, the pre-flight's probe, and a backend that goes silent
// in the middle of a grasp.
#include <gtest/gtest.h>

#include <thread>

#include "arbci/session/stages/robot_stage.h"
#include "support/robot_test_support.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

using Kind = RobotPart::Note::Kind;

// The arm's world as the session's default table has it (as the simulated cameras' world makes it).
robot::RobotConfig armFor(const WorldSettings& w) {
  robot::RobotConfig r;
  r.table_z = w.table_z;
  r.workspace_min = {-0.7, 0.2, w.table_z};
  r.workspace_max = {0.7, 1.0, w.table_z + 0.6};
  r.speed_factor = 20.0;
  for (const WorldObjectSettings& o : w.objects)
    r.objects.push_back(
        {o.id, {o.position[0], o.position[1], o.position[2]}, o.height_m, o.width_m / 2.0});
  return r;
}

class RobotStageTest : public ::testing::Test {
 protected:
  RobotStageTest() : bench_("robot") {}
  // The backend on the session's stepped clock (reproducible), or on the wall clock as a real arm.
  void connect(bool stepped = true, const robot::Key& key = robot::testKey()) {
    stepped_ = stepped;
    backend_ = std::make_unique<robot::RunningBackend>(
        std::make_unique<robot::SimulatedArm>(armFor(world_)), options(stepped));
    RobotLink link;
    link.client = std::make_unique<robot::RobotClient>(
        robot::Endpoint::resolve("127.0.0.1", backend_->port()), key, robot::fastClient());
    link.stepped = stepped;
    stage_ = std::make_unique<RobotStage>(RobotStageSettings{world_, 2}, std::move(link),
                                          bench_.services());
  }
  static robot::BackendOptions options(bool stepped) {
    robot::BackendOptions o;
    o.stepped = stepped;
    o.speed_factor = stepped ? 20.0 : 5.0;
    o.status_interval_s = 0.05;
    return o;
  }
  // Cycles until `done` holds on a record (at most `seconds` of session time); the notes seen.
  std::vector<RobotPart::Note> until(const std::function<bool(const RobotPart&)>& done,
                                     double seconds = 60.0) {
    std::vector<RobotPart::Note> notes;
    for (int i = 0; i < seconds * 60; ++i) {
      if (cameras_) cameras_(bench_.record);
      bench_.step(*stage_);
      const RobotPart& r = bench_.record.robot;
      notes.insert(notes.end(), r.notes.begin(), r.notes.end());
      const bool finished = done(r);
      bench_.next();
      if (finished) break;
      if (!stepped_) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return notes;
  }
  // The pre-flight's probe, as a session's first: a stepped backend answers it at once (the client
  // waits for the answer), one on the wall clock once its status has come.
  void probe() {
    for (int i = 0; i < 500 && !bench_.previous.robot.answered; ++i) {
      bench_.record.requests.push_back(RobotProbeRequest{bench_.record.time_s});
      bench_.step(*stage_);
      bench_.next();
      if (!bench_.previous.robot.answered)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  static bool has(const std::vector<RobotPart::Note>& notes, Kind kind, bool success) {
    for (const auto& n : notes)
      if (n.kind == kind && n.success == success) return true;
    return false;
  }
  // The tracking stage's part of each record (what the cameras see), when set: the robot stage
  // reads it on the next cycle's previous record, as in a session (tracking runs after it).
  std::function<void(CycleRecord&)> cameras_;
  // Cameras that see `id`'s top at `top` (robot frame) in every frame, with the reference.
  void camerasSee(int id, const cv::Vec3d& top) {
    auto world = std::make_shared<vision::WorldModel>(
        vision::ReferenceMarker{world_.reference_id, world_.reference_size_m,
                                {cv::Matx33d::eye(), world_.reference_position}});
    cameras_ = [this, world, id, top](CycleRecord& r) {
      // The camera at the robot's origin, axes along the robot's.
      vision::PoseEstimate reference, object;
      reference.pose = {cv::Matx33d::eye(), world_.reference_position};
      object.pose = {cv::Matx33d::eye(), top};
      world->update(r.time_s, {{world_.reference_id, reference}, {id, object}});
      r.tracking.world = std::make_shared<const vision::WorldModel>(*world);
    };
  }
  WorldSettings world_;
  bool stepped_ = true;
  test::StageBench bench_;
  std::unique_ptr<robot::RunningBackend> backend_;
  std::unique_ptr<RobotStage> stage_;
};

TEST_F(RobotStageTest, AGraspAndAPutDownAreNotedOnTheRecordWithThePlacement) {
  connect();
  const WorldObjectSettings& object = world_.objects.front();
  probe();
  ASSERT_TRUE(bench_.previous.robot.status.has_value()) << "no status from the backend";
  EXPECT_EQ(bench_.previous.robot.why_not_move, "");
  bench_.record.requests.push_back(
      GraspRequest{object.id, object.position, 0.0, 0.5, false, bench_.record.frame / 60.0});
  auto notes = until([](const RobotPart& r) {
    for (const auto& n : r.notes)
      if (n.kind == Kind::Finished) return true;
    return false;
  });
  ASSERT_TRUE(has(notes, Kind::Finished, true));
  EXPECT_EQ(bench_.previous.robot.holding(), object.id);
  EXPECT_EQ(bench_.previous.robot.grasped, object.id);
  EXPECT_FALSE(bench_.previous.robot.at_home);
  // Put down on cell (2, 2): placed, measured, the arm home and the table seen again. The
  // cameras see the object 3 mm beside the cell's centre: the placement is theirs, not the arm's
  // report (the kinematic arm lets go exactly over the centre).
  const cv::Vec3d centre = world_.grid.cellCentre(2, 2);
  camerasSee(object.id, centre + cv::Vec3d(0.003, 0.0, object.height_m));
  bench_.record.requests.push_back(DropRequest{1, {2, 2}, false, bench_.record.frame / 60.0});
  notes = until([](const RobotPart& r) {
    for (const auto& n : r.notes)
      if (n.kind == Kind::PutDownEnded) return true;
    return false;
  });
  EXPECT_TRUE(has(notes, Kind::Outcome, true));
  ASSERT_TRUE(has(notes, Kind::Placement, true));
  ASSERT_TRUE(has(notes, Kind::PutDownEnded, true));
  for (const auto& n : notes) {
    if (n.kind != Kind::Placement) continue;
    EXPECT_EQ(n.trial, 1);
    EXPECT_NEAR(n.error_m, 0.003, 1e-6);
  }
  EXPECT_TRUE(bench_.previous.robot.at_home);
  EXPECT_FALSE(bench_.previous.robot.holding().has_value());
  const auto logged = bench_.logged("placement");
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_NEAR(logged[0]["error_m"].get<double>(), 0.003, 1e-6);
  // The arm's own report of where it let go, beside the cameras' view.
  EXPECT_NEAR(logged[0]["robot_vs_cameras_m"].get<double>(), 0.003, 1e-3);
}

TEST_F(RobotStageTest, APlacementTheCamerasDidNotSeeHasNoError) {
  connect();
  const WorldObjectSettings& object = world_.objects.front();
  probe();
  bench_.record.requests.push_back(
      GraspRequest{object.id, object.position, 0.0, 0.5, false, bench_.record.frame / 60.0});
  until([](const RobotPart& r) {
    for (const auto& n : r.notes)
      if (n.kind == Kind::Finished) return true;
    return false;
  });
  bench_.record.requests.push_back(DropRequest{1, {1, 1}, false, bench_.record.frame / 60.0});
  const auto notes = until([](const RobotPart& r) {
    for (const auto& n : r.notes)
      if (n.kind == Kind::PutDownEnded) return true;
    return false;
  });
  bool measured = false;
  for (const auto& n : notes) {
    if (n.kind != Kind::Placement) continue;
    measured = true;
    EXPECT_LT(n.error_m, 0.0) << "an error the cameras never saw";
  }
  EXPECT_TRUE(measured);
  const auto logged = bench_.logged("placement");
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_TRUE(logged[0]["error_m"].is_null());
  EXPECT_EQ(logged[0]["why"], "the cameras have not seen the object since the drop");
  EXPECT_TRUE(logged[0].contains("robot_reported"));
}

TEST_F(RobotStageTest, TheExperimentersStopLatchesAndResetLiftsIt) {
  connect(false);
  const WorldObjectSettings& object = world_.objects.front();
  probe();
  bench_.record.requests.push_back(
      GraspRequest{object.id, object.position, 0.0, 0.5, false, bench_.record.frame / 60.0});
  until([](const RobotPart& r) { return r.status && r.status->progress > 0.2; });
  stage_->stopNow(bench_.record.time_s);
  until([](const RobotPart& r) { return r.status && !r.status->stop_reason.empty(); }, 5.0);
  ASSERT_FALSE(bench_.previous.robot.status->stop_reason.empty());
  EXPECT_FALSE(bench_.previous.robot.busy);
  bench_.record.requests.push_back(RobotResetRequest{bench_.record.time_s});
  until([](const RobotPart& r) { return r.status && r.status->stop_reason.empty(); }, 5.0);
  EXPECT_TRUE(bench_.previous.robot.status->stop_reason.empty());
  // Home, the experimenter's recovery, goes once nothing runs.
  bench_.record.requests.push_back(RobotHomeRequest{bench_.record.time_s});
  until([](const RobotPart& r) { return r.at_home && !r.busy; });
  EXPECT_TRUE(bench_.previous.robot.at_home);
  bool stop = false, reset = false;
  for (const auto& c : bench_.logged("robot_command")) {
    stop |= c["command"] == "STOP";
    reset |= c["command"] == "RESET";
  }
  EXPECT_TRUE(stop);
  EXPECT_TRUE(reset);
}

TEST_F(RobotStageTest, ThePreflightsProbeIsAnswered) {
  connect();
  bench_.record.requests.push_back(RobotProbeRequest{0.0});
  bench_.step(*stage_);
  EXPECT_TRUE(bench_.record.robot.answered);
}

TEST_F(RobotStageTest, ABackendThatGoesSilentInAGraspIsARobotFaultOnTheRecord) {
  connect();
  const WorldObjectSettings& object = world_.objects.front();
  probe();
  // Asked for on this cycle's frame: the arm has not moved yet when the backend goes.
  bench_.record.requests.push_back(
      GraspRequest{object.id, object.position, 0.0, 0.5, false, bench_.record.frame / 60.0});
  bench_.step(*stage_);
  ASSERT_TRUE(bench_.record.robot.busy);
  bench_.next();
  backend_->halt();
  std::vector<RobotPart::Note> notes;
  // The link is judged silent on the wall clock: a second and more without an answer.
  for (int i = 0; i < 1000 && !has(notes, Kind::Finished, false); ++i) {
    bench_.step(*stage_);
    notes.insert(notes.end(), bench_.record.robot.notes.begin(), bench_.record.robot.notes.end());
    bench_.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(has(notes, Kind::Finished, false));
  bool said = false;
  for (const auto& n : notes) said |= n.text == "robot fault: the backend went silent";
  EXPECT_TRUE(said);
  EXPECT_TRUE(bench_.previous.robot.silent);
  EXPECT_EQ(bench_.previous.robot.why_not_move, "the robot backend does not answer");
  EXPECT_TRUE(bench_.toldOf("robot: silent"));
}

// A backend whose key is not ours answers that it is not (KEY MISMATCH): on the record for the
// pre-flight, which names it, never taken for a missing backend.
TEST_F(RobotStageTest, AKeyTheBackendRefusesIsOnTheRecord) {
  robot::Key wrong = robot::testKey();
  wrong[0] ^= 0xff;
  connect(false, wrong);
  for (int i = 0; i < 1000 && !bench_.previous.robot.key_refused; ++i) {
    bench_.step(*stage_);
    bench_.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(bench_.previous.robot.key_refused);
  EXPECT_FALSE(bench_.previous.robot.status.has_value());
}

}  // namespace
}  // namespace arbci::session
