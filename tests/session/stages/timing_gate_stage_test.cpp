// The timing gate on hand-built presentations: flashes as a loaded machine shows them (too long,
// too short a dark gap, too soon) are each annotated at their onset; past the share of a
// selection's flashes the run pauses with the reason (with an experimenter), and a run without one
// carries on, annotated; late frames past their share pause it too.
#include <gtest/gtest.h>

#include <functional>

#include "arbci/session/session_config.h"
#include "arbci/session/stages/timing_gate_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

constexpr double kRate = 256.0;

TimingGateSettings gate(const std::string& policy, bool experimenter) {
  const SessionConfig c;  // the defaults: a 60 ms flash (4 frames) every 180 ms (11 frames)
  const GateSettings& g = c.gates;
  return {policy,
          timingLimitsOf(g.max_flash_ms, g.min_gap_ms, g.min_soa_ms, g.max_off_share,
                         g.max_late_share, c.paradigm),
          kRate, experimenter};
}

class TimingGateTest : public ::testing::Test {
 protected:
  explicit TimingGateTest(const std::string& policy = "pause", bool experimenter = true)
      : bench_("timing_gate"), stage_(gate(policy, experimenter), bench_.services()) {}

  // One flash of `selection` at `onset` lasting `duration` samples, presented over two cycles
  // (its onset, then its end), the paradigm flashing.
  void flash(int selection, std::int64_t onset, int duration) {
    Presentation::Onset o;
    o.flash.selection = selection;
    o.sample = onset;
    present([&](Presentation& p) { p.onsets.push_back(o); });
    present([&](Presentation& p) { p.ended.push_back({onset, duration}); });
  }
  void present(const std::function<void(Presentation&)>& what, bool late = false) {
    CycleRecord& r = bench_.record;
    r.presentation.shown = true;
    r.presentation.late = late;
    what(r.presentation);
    bench_.previous.paradigm.phase = phase_;
    bench_.step(stage_);
    for (const bci::Annotation& a : bench_.record.annotations) notes_.push_back(a);
    for (const Request& q : bench_.record.posted)
      if (const auto* p = std::get_if<PauseRequest>(&q)) pauses_.push_back(p->reason);
    bench_.next();
  }
  // `n` flashes of `selection` from sample `from`, every 46 samples (180 ms), `duration` long.
  std::int64_t flashes(int selection, std::int64_t from, int n, int duration, int soa = 46) {
    for (int k = 0; k < n; ++k) flash(selection, from + k * soa, duration);
    return from + n * soa;
  }

  test::StageBench bench_;
  TimingGateStage stage_;
  bci::Phase phase_ = bci::Phase::ObjectFlashing;
  std::vector<bci::Annotation> notes_;
  std::vector<std::string> pauses_;
};

TEST_F(TimingGateTest, FlashesWithinTheLimitsPassUnnoted) {
  flashes(1, 1000, 40, 16);  // 62.5 ms each, 180 ms apart
  EXPECT_TRUE(notes_.empty());
  EXPECT_TRUE(pauses_.empty());
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["timing_gate"]["verdict"], "within limits");
  EXPECT_NEAR(summary["timing_gate"]["limits"]["max_flash_ms"].get<double>(), 133.3, 0.1);
}

TEST_F(TimingGateTest, EveryFlashOffALimitIsAnnotatedAtItsOnset) {
  std::int64_t at = flashes(1, 1000, 5, 16);
  flash(1, at, 149);  // 582 ms: far longer than twice the flash
  at += 200;
  flash(1, at, 16);       // 199 ms dark after the long one: within the limits
  flash(1, at + 30, 16);  // 117 ms after the last onset: too soon, and a 55 ms gap
  ASSERT_GE(notes_.size(), 2u);
  EXPECT_EQ(notes_[0].sample, 1000 + 5 * 46);
  EXPECT_EQ(notes_[0].text.rfind("Timing off limits: flash lasted 582.0 ms (limit 133.3 ms)", 0),
            0u)
      << notes_[0].text;
  bool soa = false, gap = false;
  for (const bci::Annotation& a : notes_) {
    soa |=
        a.text.rfind("Timing off limits: onset-to-onset 117.2 ms", 0) == 0 && a.sample == at + 30;
    gap |= a.text.rfind("Timing off limits: dark gap before it 54.7 ms", 0) == 0;
  }
  EXPECT_TRUE(soa);
  EXPECT_TRUE(gap);
  EXPECT_EQ(bench_.logged("timing_off_limits").size(), notes_.size());
  EXPECT_TRUE(pauses_.empty());  // a few in a selection: noted, not paused
}

TEST_F(TimingGateTest, PastTheShareOfASelectionTheRunPausesWithTheReason) {
  // Every other flash twice too long: past 10 % once 12 flashes are in.
  std::int64_t at = 1000;
  for (int k = 0; k < 16 && pauses_.empty(); ++k) {
    flash(2, at, k % 2 ? 80 : 16);
    at += 100;
  }
  ASSERT_EQ(pauses_.size(), 1u);
  EXPECT_NE(pauses_[0].find("of the selection's 12 flashes off the timing limits"),
            std::string::npos)
      << pauses_[0];
  EXPECT_TRUE(bench_.toldOf("paused: timing:"));
  // Paused: no second request while it stands; resumed, it counts afresh.
  phase_ = bci::Phase::Paused;
  flashes(2, at, 4, 80, 100);
  EXPECT_EQ(pauses_.size(), 1u);
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["timing_gate"]["pauses"], 1);
  EXPECT_GT(summary["timing_gate"]["long_flashes"].get<int>(), 6);
}

TEST_F(TimingGateTest, ManyLateFramesPauseTheRun) {
  for (int k = 0; k < TimingGateStage::kLateWindow && pauses_.empty(); ++k)
    present([](Presentation&) {}, k % 3 != 0);  // two frames of three late
  ASSERT_EQ(pauses_.size(), 1u);
  EXPECT_NE(pauses_[0].find("frames presented late"), std::string::npos) << pauses_[0];
}

// Late frames before Start, in a cue or a pause time no flash: they never count. On a display
// that is late throughout, the gate pauses once, a few seconds into the flashing; the cycle after
// it asked, the paradigm has not paused yet, which is no resumption.
TEST_F(TimingGateTest, LateFramesCountOnlyWhileFlashesAreDue) {
  for (const bci::Phase not_flashing :
       {bci::Phase::Setup, bci::Phase::CalibrationCue, bci::Phase::Paused, bci::Phase::Training}) {
    phase_ = not_flashing;
    for (int k = 0; k < 2 * TimingGateStage::kLateWindow; ++k) present([](Presentation&) {}, true);
  }
  EXPECT_TRUE(pauses_.empty());
  phase_ = bci::Phase::CalibrationFlashing;
  int frames = 0;
  while (pauses_.empty() && frames < 10 * TimingGateStage::kLateWindow) {
    present([](Presentation&) {}, true);
    ++frames;
  }
  EXPECT_EQ(frames, TimingGateStage::kLateWindow);  // a whole window of flashing frames, no more
}

// Asked once: the experimenter's Resume of a timing pause carries the run on annotated, its window
// started afresh; a display late throughout never pauses the run again, and the summary says so.
TEST_F(TimingGateTest, AfterOneTimingPauseIsResumedTheRunGoesOnAnnotated) {
  while (pauses_.empty()) present([](Presentation&) {}, true);
  ASSERT_EQ(pauses_.size(), 1u);
  EXPECT_NE(pauses_[0].find("Resume: the run goes on with every flash off limits annotated"),
            std::string::npos)
      << pauses_[0];
  present([](Presentation&) {}, true);  // the paradigm has not taken the pause yet
  phase_ = bci::Phase::Paused;
  for (int k = 0; k < 30; ++k) present([](Presentation&) {}, true);
  phase_ = bci::Phase::ObjectFlashing;  // resumed
  for (int k = 0; k < 5 * TimingGateStage::kLateWindow; ++k) present([](Presentation&) {}, true);
  EXPECT_EQ(pauses_.size(), 1u);
  EXPECT_EQ(bench_.logged("timing_policy").size(), 1u);
  EXPECT_GE(bench_.logged("timing_limit").size(), 4u);  // still noted, once per late stretch
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["timing_gate"]["pauses"], 1);
  EXPECT_EQ(summary["timing_gate"]["policy_at_end"], "annotate");
}

// The pre-flight's answer for a slow display (run annotated) reaches the gate as a request: no
// timing pause in the run.
TEST_F(TimingGateTest, ARunAnnotatedFromStartNeverPausesForTiming) {
  bench_.record.requests.push_back(TimingPolicyRequest{"annotate", "the display is slow"});
  for (int k = 0; k < 3 * TimingGateStage::kLateWindow; ++k) present([](Presentation&) {}, true);
  std::int64_t at = 1000;
  for (int k = 0; k < 24; ++k, at += 100) flash(3, at, 80);
  EXPECT_TRUE(pauses_.empty());
  EXPECT_EQ(notes_.size(), 24u);
}

class UnattendedTimingGateTest : public TimingGateTest {
 protected:
  UnattendedTimingGateTest() : TimingGateTest("pause", false) {}
};

TEST_F(UnattendedTimingGateTest, WithoutAnExperimenterTheRunCarriesOnAnnotated) {
  std::int64_t at = 1000;
  for (int k = 0; k < 24; ++k, at += 100) flash(3, at, 80);
  EXPECT_TRUE(pauses_.empty());
  EXPECT_EQ(notes_.size(), 24u);
  EXPECT_FALSE(bench_.logged("timing_limit").empty());
}

}  // namespace
}  // namespace arbci::session
