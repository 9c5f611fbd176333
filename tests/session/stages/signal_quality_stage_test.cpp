// The quality gate at Start, at its own level: the signal-quality stage grades hand-made EEG
// blocks (four of eight channels broken as a lab sees them: flat, 50 Hz mains, drift, a loud
// channel), and the pre-flight stage, given that record, questions the Start (the experimenter
// may start anyway), refuses it, or ends a run without an experimenter, naming every channel.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "arbci/session/session_config.h"
#include "arbci/session/stages/preflight_stage.h"
#include "arbci/session/stages/signal_quality_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

constexpr double kRate = 256.0;
constexpr int kBlock = 16;
const std::vector<std::string> kMontage = {"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"};

// Sample `k` of channel `c`: 6 uV of pseudo-random EEG, with channels 1-4 broken.
float sampleOf(int c, std::int64_t k, double line_hz) {
  const double t = k / kRate;
  // A deterministic broadband signal: a few incommensurate sines.
  const double eeg = 3.0 * std::sin(2 * M_PI * 7.3 * t + c) + 2.5 * std::sin(2 * M_PI * 11.9 * t) +
                     2.0 * std::sin(2 * M_PI * 3.1 * t + 2 * c) +
                     1.5 * std::sin(2 * M_PI * 23.7 * t);
  switch (c) {
    case 1:
      return 0.05f * static_cast<float>(std::sin(2 * M_PI * 9.0 * t));  // flat
    case 2:
      return static_cast<float>(eeg + 29.0 * std::sin(2 * M_PI * line_hz * t));  // mains
    case 3:
      return static_cast<float>(eeg + 274.0 * t);  // drifting
    case 4:
      return static_cast<float>(eeg * 40.0);  // loud: RMS over 100 uV
    default:
      return static_cast<float>(eeg);
  }
}

bci::Block blockAt(std::int64_t first, double line_hz) {
  bci::Block b(first, static_cast<int>(kMontage.size()), kBlock);
  for (int s = 0; s < kBlock; ++s)
    for (int c = 0; c < b.channels; ++c) b.at(c, s) = sampleOf(c, first + s, line_hz);
  return b;
}

SignalQualitySettings qualitySettings(double notch_hz) {
  bci::SignalInfo info;
  info.channels = kMontage;
  info.rate_hz = kRate;
  GateSettings gates;
  return {info, gates.thresholds(notch_hz)};
}

// Three seconds of blocks through the stage; the record it wrote last.
QualityPart graded(double line_hz, double notch_hz) {
  test::StageBench bench("quality_" + std::to_string(static_cast<int>(line_hz)));
  SignalQualityStage stage(qualitySettings(notch_hz));
  for (std::int64_t k = 0; k < 3 * static_cast<std::int64_t>(kRate); k += kBlock) {
    bench.record.eeg.eeg_blocks = {blockAt(k, line_hz)};
    bench.step(stage);
    bench.next();
  }
  return bench.previous.quality;
}

TEST(SignalQualityStage, GradesEachChannelAndNamesWhatIsWrong) {
  const QualityPart q = graded(50.0, 50.0);
  ASSERT_EQ(q.quality.size(), kMontage.size());
  const std::vector<std::string> bad = q.bad();
  ASSERT_EQ(bad.size(), 4u) << nlohmann::json(bad).dump();
  EXPECT_EQ(bad[0].rfind("Cz: flat", 0), 0u) << bad[0];
  EXPECT_EQ(bad[1].rfind("P3: line noise 50 Hz", 0), 0u) << bad[1];
  EXPECT_EQ(bad[2].rfind("Pz: drift", 0), 0u) << bad[2];
  EXPECT_EQ(bad[3].rfind("P4: RMS", 0), 0u) << bad[3];
  EXPECT_EQ(q.toJson()[0]["grade"], "good");
}

TEST(SignalQualityStage, GradesOnlyTheLabsLineFrequency) {
  // 60 Hz at 29 uV where the notch (the lab's mains) is 50 Hz: not graded as line noise.
  const QualityPart q = graded(60.0, 50.0);
  for (const std::string& b : q.bad()) EXPECT_EQ(b.find("line noise"), std::string::npos) << b;
}

PreflightStageSettings gateSettings(const std::string& gate, bool experimenter) {
  PreflightStageSettings s;
  s.check.eeg_rate_hz = kRate;
  s.check.camera_key = "cameras.source";
  s.check.camera_what = "the simulated cameras";
  s.check.eeg_key = "eeg.file";
  s.check.robot_key = "robot.backend";
  s.check.robot_what = "the simulated arm";
  s.check.quality_gate = gate;
  // A failing check waits this long in session and wall time both: short, so the tests wait little.
  s.check.min_s = 0.2;
  s.check.timeout_s = 0.6;
  s.experimenter = experimenter;
  s.max_pose_age_s = 0.5;
  return s;
}

// A healthy set-up but for the channels the quality part names.
void setUp(CycleRecord& r, const QualityPart& quality) {
  const double t = r.time_s;
  r.cameras.left = cv::Mat(4, 4, CV_8UC3);
  vision::WorldModel world;
  vision::PoseEstimate p;
  p.pose = {cv::Matx33d::eye(), cv::Vec3d(0, 0, 1)};
  world.update(t, {{0, p}});
  r.tracking.world = std::make_shared<const vision::WorldModel>(world);
  r.recording.samples = static_cast<std::int64_t>(t * kRate) / 16 * 16;
  r.robot.answered = true;
  r.quality = quality;
}

// Steps the pre-flight until it has logged its verdict (or posted Begin); returns Begin's count.
int runCheck(test::StageBench& bench, PreflightStage& stage, const QualityPart& quality,
             StartRequest start) {
  bench.record.requests.push_back(start);
  const size_t logged = bench.logged("preflight").size();
  int begins = 0;
  for (int i = 0; i < 20000 && bench.logged("preflight").size() == logged; ++i) {
    setUp(bench.record, quality);
    bench.step(stage);
    for (const Request& r : bench.record.posted) begins += std::holds_alternative<BeginRequest>(r);
    if (!bench.record.end_reason.empty()) break;
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return begins;
}

TEST(QualityGate, AskQuestionsTheStartAndTheExperimenterMayStartAnyway) {
  const QualityPart bad = graded(50.0, 50.0);
  test::StageBench bench("gate_ask");
  PreflightStage stage(gateSettings("ask", true), bench.services());
  EXPECT_EQ(runCheck(bench, stage, bad, StartRequest{}), 0);
  EXPECT_TRUE(bench.previous.end_reason.empty());
  EXPECT_EQ(bench.logged("preflight").back()["failures"].size(), 1u)
      << bench.logged("preflight").back().dump();
  // The panel's question names every bad channel with its reason.
  ASSERT_EQ(bench.previous.preflight.questioned.size(), 4u);
  EXPECT_EQ(bench.previous.preflight.questioned[0].rfind("Cz: flat", 0), 0u);
  EXPECT_TRUE(bench.toldOf("4 of 8 EEG channels bad"));
  EXPECT_EQ(bench.logged("signal_quality").back()["verdict"], "questioned");
  // Start anyway: the check passes with the channels as they are, and says so everywhere.
  EXPECT_EQ(runCheck(bench, stage, bad, StartRequest{true}), 1);
  const nlohmann::json verdict = bench.logged("signal_quality").back();
  EXPECT_EQ(verdict["verdict"], "accepted by the experimenter");
  EXPECT_EQ(verdict["bad_channels"], 4);
  bool annotated = false;
  for (const bci::Annotation& a : bench.previous.annotations)
    annotated |=
        a.text.rfind("Signal quality at Start: accepted by the experimenter, 4 of 8", 0) == 0;
  EXPECT_TRUE(annotated);
  nlohmann::json summary;
  stage.report(summary);
  EXPECT_EQ(summary["signal_quality"]["verdict"], "accepted by the experimenter");
  EXPECT_EQ(summary["signal_quality"]["channels"].size(), 8u);
}

TEST(QualityGate, RefuseCannotBeStartedAnyway) {
  const QualityPart bad = graded(50.0, 50.0);
  test::StageBench bench("gate_refuse");
  PreflightStage stage(gateSettings("refuse", true), bench.services());
  EXPECT_EQ(runCheck(bench, stage, bad, StartRequest{}), 0);
  EXPECT_TRUE(bench.previous.preflight.questioned.empty());
  EXPECT_EQ(runCheck(bench, stage, bad, StartRequest{true}), 0);
  EXPECT_EQ(bench.logged("signal_quality").back()["verdict"], "refused");
  EXPECT_TRUE(bench.toldOf("pre-flight failed: gates.signal_quality: 4 of 8"));
}

TEST(QualityGate, WithoutAnExperimenterTheRunEndsNamingEachChannel) {
  const QualityPart bad = graded(50.0, 50.0);
  test::StageBench bench("gate_unattended");
  PreflightStage stage(gateSettings("ask", false), bench.services());
  EXPECT_EQ(runCheck(bench, stage, bad, StartRequest{}), 0);
  const std::string& ended = bench.record.end_reason;
  for (const char* channel : {"Cz: flat", "P3: line noise 50 Hz", "Pz: drift", "P4: RMS"})
    EXPECT_NE(ended.find(channel), std::string::npos) << ended;
  EXPECT_EQ(bench.record.end_kind, "aborted");
}

TEST(QualityGate, GoodChannelsPass) {
  const QualityPart good = graded(50.0, 60.0);  // mains at 50 Hz where the lab's is 60 Hz
  QualityPart healthy = good;
  for (size_t c = 0; c < healthy.quality.size(); ++c)
    if (healthy.quality[c].grade == bci::Grade::Bad) healthy.quality[c].grade = bci::Grade::Good;
  test::StageBench bench("gate_pass");
  PreflightStage stage(gateSettings("refuse", false), bench.services());
  EXPECT_EQ(runCheck(bench, stage, healthy, StartRequest{}), 1);
  EXPECT_EQ(bench.logged("signal_quality").back()["verdict"], "passed");
}

}  // namespace
}  // namespace arbci::session
