// The presentation stage on hand-built records: the frame drawn last cycle, once presented, as the
// screen showed it — each flash stamped with the presentation of its first frame, its duration to
// the first frame without it, the photodiode patch as read back, late frames, a slow display.
#include <gtest/gtest.h>

#include "arbci/session/stages/presentation_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

class PresentationStageTest : public ::testing::Test {
 protected:
  PresentationStageTest()
      : bench_("presentation"), stage_(PresentationSettings{{}, 256.0}, bench_.services()) {}
  // The last cycle's frame showed `lit` (of which `first` for the first time) and reached the
  // screen `late_s` after it was due, at EEG sample `sample`.
  void drawn(std::set<int> lit, std::vector<int> first, std::int64_t sample, double late_s = 0.0) {
    CycleRecord& p = bench_.previous;
    p.due_s = p.frame / 60.0;
    p.paradigm.stimulus.lit = std::move(lit);
    for (int code : first) p.paradigm.first_shown.push_back({code, true, code == 2, true, 1});
    p.presented = CycleRecord::Presented{bench_.clock().hostOf(p.due_s + late_s), sample};
  }
  void step() {
    bench_.step(stage_);
    bench_.next();
  }
  const Presentation& shown() const { return bench_.previous.presentation; }
  test::StageBench bench_;
  PresentationStage stage_;
};

TEST_F(PresentationStageTest, AFlashIsStampedAtItsFirstFrameAndLastsUntilTheFirstFrameWithoutIt) {
  bench_.previous.frame = 10;
  drawn({2}, {2}, 43);
  step();
  ASSERT_TRUE(shown().shown);
  ASSERT_EQ(shown().onsets.size(), 1u);
  EXPECT_EQ(shown().onsets[0].flash.code, 2);
  EXPECT_TRUE(shown().onsets[0].flash.target);
  EXPECT_EQ(shown().onsets[0].sample, 43);
  EXPECT_EQ(shown().frame, 10);
  // Three more frames lit, then one without it: its duration runs to that frame's sample.
  for (std::int64_t sample : {47, 51, 56}) {
    drawn({2}, {}, sample);
    step();
    EXPECT_TRUE(shown().onsets.empty());
    EXPECT_TRUE(shown().ended.empty());
  }
  drawn({}, {}, 60);
  step();
  ASSERT_EQ(shown().ended.size(), 1u);
  EXPECT_EQ(shown().ended[0].onset_sample, 43);
  EXPECT_EQ(shown().ended[0].duration_samples, 17);
}

// A selection whose flashing stood still for an E-STOP: its time is its flashes' (first onset to
// last, plus one SOA) without the stop, which is reported apart.
TEST_F(PresentationStageTest, TimeInterruptedIsLeftOutOfTheSelectionsTime) {
  auto frameAt = [&](bool flash, bci::Phase phase) {
    CycleRecord& p = bench_.previous;
    p.paradigm.phase = phase;
    const std::int64_t sample = std::llround(p.frame / 60.0 * 256.0);
    if (flash) {
      drawn({1}, {1}, sample);
    } else {
      drawn({}, {}, sample);
    }
    step();
  };
  bench_.previous.paradigm.selection_started = SelectionStart{};
  // Flashes every 12 frames (200 ms), three of them; 120 frames (2 s) stopped; two more.
  for (int f = 0; f < 36; ++f) frameAt(f % 12 == 0, bci::Phase::ObjectFlashing);
  for (int f = 0; f < 120; ++f) frameAt(false, bci::Phase::EmergencyStop);
  for (int f = 0; f < 13; ++f) frameAt(f % 12 == 0, bci::Phase::ObjectFlashing);
  EXPECT_NEAR(shown().selection_interrupted_s, 2.0, 0.05);
  // Five flashes: four intervals and one SOA, 1.0 s, whatever the stop's length.
  EXPECT_NEAR(shown().selection_s, 1.0, 0.05);
}

TEST_F(PresentationStageTest, NothingIsStampedForAFrameNotYetPresented) {
  bench_.previous.paradigm.first_shown.push_back({3, true, false, true, 1});
  bench_.previous.paradigm.stimulus.lit = {3};
  step();
  EXPECT_FALSE(shown().shown);
  EXPECT_TRUE(shown().onsets.empty());
}

TEST_F(PresentationStageTest, AFrameOverAPeriodLateIsLoggedAndCounted) {
  bench_.previous.frame = 4;
  drawn({}, {}, 20, 0.030);
  step();
  EXPECT_TRUE(shown().late);
  EXPECT_EQ(shown().late_frames, 1);
  const auto late = bench_.logged("late_frame");
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0]["frame"], 4);
  EXPECT_NEAR(late[0]["late_ms"].get<double>(), 30.0, 1e-6);
}

TEST_F(PresentationStageTest, ThePhotodiodePatchIsWhatTheFrameDrawnShowed) {
  drawn({1}, {1}, 0);
  // The render stage read the patch back lit from the frame it drew.
  bench_.previous.display = {true, true, true};
  step();
  ASSERT_TRUE(shown().patch.has_value());
  EXPECT_TRUE(*shown().patch);
  // An unchanged frame (not redrawn) shows what the last one did: no change to report.
  drawn({1}, {}, 4);
  bench_.previous.display = {false, std::nullopt, true};
  step();
  EXPECT_FALSE(shown().patch.has_value());
  drawn({}, {}, 8);
  bench_.previous.display = {true, false, true};
  step();
  ASSERT_TRUE(shown().patch.has_value());
  EXPECT_FALSE(*shown().patch);
}

TEST_F(PresentationStageTest, AFeedbackFirstShownIsPassedOnWithItsSample) {
  drawn({}, {}, 99);
  bench_.previous.paradigm.feedback = FeedbackShown{{3}, true, false};
  step();
  ASSERT_TRUE(shown().feedback.has_value());
  EXPECT_EQ(shown().feedback->codes, std::set<int>{3});
  EXPECT_EQ(shown().sample, 99);
}

TEST_F(PresentationStageTest, ADisplayThatCannotHoldItsRateIsSaidOnce) {
  // Every frame presented two periods after the last: 30 Hz against 60 configured.
  for (int frame = 0; frame < 130; ++frame) {
    bench_.previous.frame = frame;
    CycleRecord& p = bench_.previous;
    p.due_s = frame / 60.0;
    p.presented = CycleRecord::Presented{bench_.clock().hostOf(2.0 * frame / 60.0), frame * 8};
    bench_.record.frame = frame + 1;
    step();
  }
  EXPECT_TRUE(shown().display_too_slow);
  ASSERT_TRUE(shown().median_frame_ms.has_value());
  EXPECT_NEAR(*shown().median_frame_ms, 33.3, 0.1);
  EXPECT_EQ(bench_.logged("display_too_slow").size(), 1u);
  EXPECT_TRUE(bench_.toldOf("the display shows a frame every 33.3 ms"));
}

}  // namespace
}  // namespace arbci::session
