// The pre-flight check's verdicts from observations alone (no session): a healthy set-up passes,
// a failure known before the check (the display's) fails it on its first frame, naming the key.
#include "arbci/session/preflight.h"

#include "arbci/session/disk_estimate.h"

#include <gtest/gtest.h>

namespace arbci::session {
namespace {

PreflightSettings settings() {
  PreflightSettings s;
  s.eeg_rate_hz = 256.0;
  s.camera_key = "cameras.source";
  s.camera_what = "the simulated cameras";
  s.eeg_key = "eeg.rate_hz";
  s.robot_key = "robot.backend";
  s.robot_what = "the simulated arm";
  return s;
}

// Frame `i` of a healthy set-up at 60 Hz: pictures with the reference, 256 Hz in 15-sample
// blocks, a robot that answers.
PreflightObservation healthy(int i) {
  PreflightObservation o;
  o.time_s = o.wall_s = i / 60.0;
  o.camera_frame = true;
  o.reference_age_s = 0.0;
  o.eeg_samples = static_cast<long long>(o.time_s * 256.0) / 15 * 15;
  o.robot_answered = true;
  return o;
}

TEST(Preflight, AHealthySetUpPassesAfterItsMinimumTime) {
  Preflight p(settings());
  p.begin(healthy(0));
  Preflight::State state = Preflight::State::Running;
  int frame = 1;
  for (; frame < 600 && state == Preflight::State::Running; ++frame)
    state = p.update(healthy(frame));
  EXPECT_EQ(state, Preflight::State::Passed);
  EXPECT_NEAR(p.eegRateHz(), 256.0, 256.0 * 0.1);
}

TEST(Preflight, AFailureTheDisplayFoundFailsOnTheFirstFrameNamingItsKey) {
  PreflightSettings s = settings();
  s.known_failures = {"hmd.mirror_monitor = 3: there is no such monitor"};
  Preflight p(s);
  p.begin(healthy(0));
  EXPECT_EQ(p.update(healthy(1)), Preflight::State::Failed);
  ASSERT_FALSE(p.failures().empty());
  EXPECT_EQ(p.failures().front(), "hmd.mirror_monitor = 3: there is no such monitor");
  ASSERT_GE(p.lines().size(), 2u);
  EXPECT_NE(p.lines()[1].find("hmd.mirror_monitor = 3"), std::string::npos);
}

// A display that shows a frame every 110 ms where 60 Hz is asked: a question before Start with
// the figures (what the flashes will last), which the experimenter may accept (run annotated);
// one that holds its rate passes. Frames from before the check do not count.
TEST(Preflight, ADisplayTooSlowForItsRateIsAQuestionWithTheFigures) {
  PreflightSettings s = settings();
  s.display_hz = 60.0;
  s.flash_ms = 60.0;
  s.soa_ms = 180.0;
  s.display_question = true;
  auto slow = [](int i) {
    PreflightObservation o = healthy(i);
    if (i % 7 == 0) o.frame_host_s = 100.0 + i / 60.0;  // every 7th cycle: 117 ms apart
    return o;
  };
  Preflight p(s);
  p.begin(slow(0));
  Preflight::State state = Preflight::State::Running;
  for (int frame = 1; frame < 2000 && state == Preflight::State::Running; ++frame)
    state = p.update(slow(frame));
  ASSERT_EQ(state, Preflight::State::Failed);
  EXPECT_TRUE(p.questioned());
  EXPECT_FALSE(p.qualityQuestioned());
  ASSERT_EQ(p.failures().size(), 1u);
  EXPECT_EQ(p.failures()[0].rfind("display: a frame every 117 ms (8.6 Hz; display_hz 60 asks for "
                                  "16.7 ms): flashes will last about 117 ms instead of 67, and "
                                  "onsets come about 233 ms apart instead of 183",
                                  0),
            0u)
      << p.failures()[0];
  EXPECT_NE(p.failures()[0].find("run annotated"), std::string::npos);
  // Accepted: the check passes, and says the display was accepted.
  p.begin(slow(2000), {false, true});
  state = Preflight::State::Running;
  for (int frame = 2001; frame < 4000 && state == Preflight::State::Running; ++frame)
    state = p.update(slow(frame));
  EXPECT_EQ(state, Preflight::State::Passed);
  EXPECT_TRUE(p.displayAccepted());
  // A display at its rate passes unasked.
  Preflight steady(s);
  steady.begin(healthy(0));
  state = Preflight::State::Running;
  for (int frame = 1; frame < 600 && state == Preflight::State::Running; ++frame) {
    PreflightObservation o = healthy(frame);
    o.frame_host_s = frame / 60.0;
    state = steady.update(o);
  }
  EXPECT_EQ(state, Preflight::State::Passed);
}

TEST(Preflight, FewerThanTwoObjectsInViewFailNamingThoseNotSeen) {
  PreflightSettings s = settings();
  s.object_ids = {10, 20, 30, 40};
  s.timeout_s = 2.0;
  Preflight p(s);
  p.begin(healthy(0));
  Preflight::State state = Preflight::State::Running;
  for (int frame = 1; frame < 600 && state == Preflight::State::Running; ++frame) {
    PreflightObservation o = healthy(frame);
    o.objects_seen = {20};  // the others off the table
    state = p.update(o);
  }
  ASSERT_EQ(state, Preflight::State::Failed);
  ASSERT_EQ(p.failures().size(), 1u);
  EXPECT_EQ(p.failures()[0].rfind("world.objects: 1 of the 4 objects seen", 0), 0u)
      << p.failures()[0];
  EXPECT_NE(p.failures()[0].find("not seen: 10, 30, 40"), std::string::npos);
  // Two seen (at some time during the check) are enough.
  Preflight again(s);
  again.begin(healthy(0));
  state = Preflight::State::Running;
  for (int frame = 1; frame < 600 && state == Preflight::State::Running; ++frame) {
    PreflightObservation o = healthy(frame);
    o.objects_seen = {frame % 2 ? 20 : 40};
    state = again.update(o);
  }
  EXPECT_EQ(state, Preflight::State::Passed);
}

TEST(Preflight, ADiskThatCannotHoldThePlannedRunFailsSayingHowMuchIsNeeded) {
  PreflightSettings s = settings();
  s.disk_needed = 85'000'000;
  s.folder = "/data/day1";
  s.disk_what = "about 85 MB: twice the 26 min planned";
  Preflight p(s);
  p.begin(healthy(0));
  Preflight::State state = Preflight::State::Running;
  for (int frame = 1; frame < 600 && state == Preflight::State::Running; ++frame) {
    PreflightObservation o = healthy(frame);
    o.disk_free = 12'400'000;
    state = p.update(o);
  }
  ASSERT_EQ(state, Preflight::State::Failed);
  ASSERT_EQ(p.failures().size(), 1u);
  EXPECT_EQ(p.failures().front(),
            "--out: the disk holding /data/day1 has 12 MB free; this run needs about 85 MB: "
            "twice the 26 min planned: free some space, choose another folder, or keep fewer "
            "screenshots (hmd.screenshots)");
  // With the space there, the same set-up passes.
  Preflight enough(s);
  enough.begin(healthy(0));
  state = Preflight::State::Running;
  for (int frame = 1; frame < 600 && state == Preflight::State::Running; ++frame) {
    PreflightObservation o = healthy(frame);
    o.disk_free = 200'000'000;
    state = enough.update(o);
  }
  EXPECT_EQ(state, Preflight::State::Passed);
}

// The estimate grows with the trials, the channels and the screenshots kept, and says so.
TEST(DiskEstimate, TheRunsFilesFromItsSettings) {
  SessionConfig c;
  const DiskEstimate base = plannedRunBytes(c, 9, 256.0);
  EXPECT_GT(base.planned_s, 60.0);
  EXPECT_NE(base.what.find("hmd.screenshots \"phases\""), std::string::npos) << base.what;
  c.paradigm.trials *= 10;
  const DiskEstimate longer = plannedRunBytes(c, 9, 256.0);
  EXPECT_GT(longer.bytes, 5 * base.bytes);
  c.hmd.screenshots = "none";
  const DiskEstimate fewer = plannedRunBytes(c, 9, 256.0);
  EXPECT_LT(fewer.bytes, longer.bytes / 2);
  EXPECT_GT(plannedRunBytes(c, 64, 2048.0).bytes, 20 * fewer.bytes);
}

}  // namespace
}  // namespace arbci::session
