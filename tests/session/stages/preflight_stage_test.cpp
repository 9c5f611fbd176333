// The pre-flight stage on hand-built records: Start begins the check; healthy cameras, reference,
// EEG and robot pass it and post Begin for the paradigm; a failure names the key in the log and
// to the experimenter, and without an experimenter ends the run before any flash.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "arbci/session/stages/preflight_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

PreflightStageSettings settings(bool experimenter) {
  PreflightStageSettings s;
  s.check.eeg_rate_hz = 256.0;
  s.check.camera_key = "cameras.left.video";
  s.check.camera_what = "the video scene.mp4";
  s.check.eeg_key = "eeg.rate_hz";
  s.check.reference_id = 0;
  s.check.robot_key = "robot.host, robot.port";
  s.check.robot_what = "the robot backend at 10.0.0.5:5005";
  s.experimenter = experimenter;
  s.max_pose_age_s = 0.5;
  // It fails past this many seconds of session time and of the wall clock both (a robot answers
  // on the wall clock): short, so the failing tests wait little.
  s.check.timeout_s = 0.5;
  return s;
}

// Frame `frame`'s record as a healthy set-up writes it (the robot answering unless told).
void healthy(CycleRecord& r, bool robot_answers = true, bool reference = true) {
  const double t = r.frame / 60.0;
  r.cameras.left = cv::Mat(4, 4, CV_8UC3);
  vision::WorldModel world;
  if (reference) {
    vision::PoseEstimate p;
    p.pose = {cv::Matx33d::eye(), cv::Vec3d(0, 0, 1)};
    world.update(t, {{0, p}});
  }
  r.tracking.world = std::make_shared<const vision::WorldModel>(world);
  r.recording.samples = static_cast<std::int64_t>(t * 256.0) / 15 * 15;
  r.robot.answered = robot_answers;
}

int count(const std::vector<Request>& requests, bool begin) {
  int n = 0;
  for (const Request& r : requests)
    n += begin ? std::holds_alternative<BeginRequest>(r)
               : std::holds_alternative<RobotProbeRequest>(r);
  return n;
}

TEST(PreflightStage, StartChecksAHealthySetUpAndPostsBegin) {
  test::StageBench bench("preflight_pass");
  PreflightStage stage(settings(true), bench.services());
  // Nothing happens before Start.
  bench.run(stage, 10, [](CycleRecord& r) { healthy(r); });
  EXPECT_FALSE(bench.previous.preflight.running);
  EXPECT_TRUE(bench.previous.preflight.lines.empty());
  bench.record.requests.push_back(StartRequest{});
  int begins = 0, probes = 0;
  for (int i = 0; i < 600 && begins == 0; ++i) {
    healthy(bench.record);
    bench.step(stage);
    begins += count(bench.record.posted, true);
    probes += count(bench.record.posted, false);
    bench.next();
  }
  EXPECT_EQ(begins, 1);
  EXPECT_GT(probes, 0);  // the robot is asked on every frame of the check
  EXPECT_FALSE(bench.previous.preflight.running);
  EXPECT_TRUE(bench.toldOf("pre-flight passed"));
  const auto logged = bench.logged("preflight");
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_TRUE(logged[0]["passed"].get<bool>());
}

TEST(PreflightStage, ARobotThatNeverAnswersFailsNamingTheKeyAndEndsARunWithoutExperimenter) {
  test::StageBench bench("preflight_robot");
  PreflightStage stage(settings(false), bench.services());
  bench.record.requests.push_back(StartRequest{});
  std::string ended;
  for (int i = 0; i < 20000 && ended.empty(); ++i) {
    healthy(bench.record, false);
    bench.step(stage);
    EXPECT_EQ(count(bench.record.posted, true), 0);
    ended = bench.record.end_reason;
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_NE(ended.find("pre-flight failed"), std::string::npos) << ended;
  EXPECT_NE(ended.find("robot.host, robot.port"), std::string::npos) << ended;
  EXPECT_EQ(bench.previous.end_kind, "aborted");
  EXPECT_TRUE(bench.toldOf("pre-flight failed"));
}

TEST(PreflightStage, WithAnExperimenterAFailureIsShownAndStartCanBeTriedAgain) {
  test::StageBench bench("preflight_again");
  PreflightStage stage(settings(true), bench.services());
  bench.record.requests.push_back(StartRequest{});
  for (int i = 0; i < 20000 && bench.logged("preflight").empty(); ++i) {
    healthy(bench.record, true, false);  // the reference marker never in view
    bench.step(stage);
    EXPECT_TRUE(bench.record.end_reason.empty());
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const auto failed = bench.logged("preflight");
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_FALSE(failed[0]["passed"].get<bool>());
  EXPECT_NE(failed[0]["failures"].dump().find("reference marker 0"), std::string::npos)
      << failed[0].dump();
  bool shown = false;
  for (const std::string& line : bench.previous.preflight.lines)
    shown |= line.find("FAILED") != std::string::npos;
  EXPECT_TRUE(shown);
  // The marker brought into view, Start again: it passes.
  bench.record.requests.push_back(StartRequest{});
  int begins = 0;
  for (int i = 0; i < 600 && begins == 0; ++i) {
    healthy(bench.record);
    bench.step(stage);
    begins += count(bench.record.posted, true);
    bench.next();
  }
  EXPECT_EQ(begins, 1);
}

TEST(PreflightStage, ARobotThatRefusesOurKeyIsNamedAsSuch) {
  test::StageBench bench("preflight_key");
  PreflightStage stage(settings(false), bench.services());
  bench.record.requests.push_back(StartRequest{});
  std::string ended;
  for (int i = 0; i < 20000 && ended.empty(); ++i) {
    healthy(bench.record, false);
    bench.record.robot.key_refused = true;
    bench.step(stage);
    ended = bench.record.end_reason;
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_NE(ended.find("robot.host, robot.port: the robot backend at 10.0.0.5:5005 answered that "
                       "our key is not its key"),
            std::string::npos)
      << ended;
}

}  // namespace
}  // namespace arbci::session
