// The pre-flight check's verdicts from observations alone (no session): a healthy set-up passes,
// a failure known before the check (the display's) fails it on its first frame, naming the key.
#include "arbci/session/preflight.h"

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

}  // namespace
}  // namespace arbci::session
