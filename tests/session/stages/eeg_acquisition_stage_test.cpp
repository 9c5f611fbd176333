// The EEG acquisition stage on hand-built records, over a scripted source: what arrived by the
// cycle's time is taken (the photodiode split off the EEG), what the screen showed and what the
// subject attends reach the source, lost samples are counted and told, a live source's fault is
// named once when it starts and once when it ends, and a delivery held up marks the flash stamps
// that rest on it — the flash the presentation stage stamped in the very cycle the stall is taken
// among them.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "arbci/session/stages/eeg_acquisition_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

// Fz, Cz and a photodiode at 256 Hz: Fz counts the samples, the photodiode is 1000 uV. Blocks come
// as the clock makes them available; `gap` skips that many samples once, `hold` keeps everything
// back until released.
class ScriptedSource final : public bci::EegSource {
 public:
  explicit ScriptedSource(std::shared_ptr<const bci::SampleClock> clock)
      : clock_(std::move(clock)) {
    info_.rate_hz = 256.0;
    info_.block_size = 16;
    info_.channels = {"Fz", "Cz", "Photodiode"};
  }
  const bci::SignalInfo& info() const override { return info_; }
  std::vector<bci::Block> poll(int max_blocks) override {
    std::vector<bci::Block> out;
    if (hold) return out;
    const std::int64_t available = clock_->available(info_.rate_hz);
    while (next_ + 16 <= available && static_cast<int>(out.size()) < max_blocks &&
           (ends_at == 0 || next_ < ends_at)) {
      if (gap > 0) {
        next_ += gap.exchange(0);
        continue;
      }
      bci::Block b(next_, 3, 16);
      for (int k = 0; k < 16; ++k) {
        b.at(0, k) = static_cast<float>(next_ + k);
        b.at(2, k) = 1000.0f;
      }
      out.push_back(std::move(b));
      next_ += 16;
    }
    return out;
  }
  void present(const bci::StimulusEvent& e) override {
    std::lock_guard lock(mutex);
    presented.push_back(e);
  }
  void attend(const std::set<int>& codes) override {
    std::lock_guard lock(mutex);
    attended = codes;
  }
  void feedback(std::int64_t sample, const std::set<int>& codes) override {
    std::lock_guard lock(mutex);
    feedbacks.emplace_back(sample, codes);
  }
  void displayed(double, bool lit) override {
    std::lock_guard lock(mutex);
    patches.push_back(lit);
  }
  std::string fault() const override {
    std::lock_guard lock(mutex);
    return fault_text;
  }
  std::string impedance() const override { return "Fz 4.2, Cz 12"; }
  bool finished() const override { return ends_at > 0 && next_ >= ends_at; }
  std::vector<bci::Annotation> takeAnnotations() override {
    std::lock_guard lock(mutex);
    return std::exchange(markers, {});
  }

  std::atomic<std::int64_t> gap{0};
  std::int64_t ends_at = 0;  // a finite source (a file): no sample from here on (0: endless)
  std::atomic<bool> hold{false};
  mutable std::mutex mutex;
  std::string fault_text;
  std::vector<bci::StimulusEvent> presented;
  std::set<int> attended;
  std::vector<std::pair<std::int64_t, std::set<int>>> feedbacks;
  std::vector<bool> patches;
  std::vector<bci::Annotation> markers;  // the amplifier's own, as an RDA stream carries them

 private:
  std::shared_ptr<const bci::SampleClock> clock_;
  bci::SignalInfo info_;
  std::int64_t next_ = 0;
};

EegAcquisitionSettings settings(const std::string& photodiode = "Photodiode",
                                bool experimenter = true) {
  EegAcquisitionSettings s;
  s.experimenter = experimenter;
  s.eeg.photodiode_channel = photodiode;
  s.flash_s = 4.0 / 60.0;
  s.session_file = "test.json";
  return s;
}

struct Acquiring {
  explicit Acquiring(test::StageBench& bench, const std::string& photodiode = "Photodiode",
                     bool experimenter = true) {
    OpenedEegSource opened;
    opened.clock = bench.clock().sourceClock(0.0);
    auto own = std::make_unique<ScriptedSource>(opened.clock);
    source = own.get();
    opened.source = std::move(own);
    stage = std::make_unique<EegAcquisitionStage>(
        settings(photodiode, experimenter), std::move(opened), bench.clock(), bench.services());
  }
  ScriptedSource* source;
  std::unique_ptr<EegAcquisitionStage> stage;
};

TEST(EegAcquisitionStage, WhatArrivedByTheCyclesTimeIsTakenWithThePhotodiodeApart) {
  test::StageBench bench("eeg_take");
  Acquiring eeg(bench);
  std::int64_t samples = 0;
  for (int frame = 0; frame < 60; ++frame) {
    const Cycle c = bench.step(*eeg.stage);
    for (const bci::Block& b : bench.record.eeg.blocks) {
      EXPECT_EQ(b.channels, 3);
      EXPECT_EQ(b.first_sample, samples);
      samples += b.samples;
    }
    ASSERT_EQ(bench.record.eeg.blocks.size(), bench.record.eeg.eeg_blocks.size());
    for (const bci::Block& b : bench.record.eeg.eeg_blocks) {
      EXPECT_EQ(b.channels, 2);
      EXPECT_EQ(b.at(0, 0), static_cast<float>(b.first_sample));
    }
    // Stepped: every block complete by the cycle's time, and the cycle stamped with its sample.
    EXPECT_EQ(samples, static_cast<std::int64_t>(frame / 60.0 * 256.0 + 1e-9) / 16 * 16);
    EXPECT_EQ(c.eeg_sample, bench.record.eeg_sample);
    bench.next();
  }
  EXPECT_EQ(bench.previous.eeg.info->channels.size(), 3u);
  EXPECT_EQ(bench.previous.eeg.impedance, "Fz 4.2, Cz 12");
  EXPECT_EQ(bench.previous.eeg.lost_samples, 0);
}

TEST(EegAcquisitionStage, TheScreenAndTheSubjectsAttentionReachTheSource) {
  test::StageBench bench("eeg_source_told");
  Acquiring eeg(bench);
  SelectionStart start;
  start.attended = {2};
  bench.previous.paradigm.selection_started = start;
  bench.record.presentation.onsets.push_back({Flash{2, true, true, true, 1}, 40});
  bench.record.presentation.patch = true;
  bench.record.presentation.feedback = FeedbackShown{{3}, true, std::nullopt};
  bench.record.presentation.sample = 44;
  bench.step(*eeg.stage);
  std::lock_guard lock(eeg.source->mutex);
  EXPECT_EQ(eeg.source->attended, std::set<int>{2});
  ASSERT_EQ(eeg.source->presented.size(), 1u);
  EXPECT_EQ(eeg.source->presented[0].sample, 40);
  EXPECT_TRUE(eeg.source->presented[0].target);
  // The flash's nominal duration: 4 frames at 60 Hz, in samples.
  EXPECT_EQ(eeg.source->presented[0].duration_samples, 17);
  EXPECT_EQ(eeg.source->patches, std::vector<bool>{true});
  ASSERT_EQ(eeg.source->feedbacks.size(), 1u);
  EXPECT_EQ(eeg.source->feedbacks[0].first, 44);
}

TEST(EegAcquisitionStage, LostSamplesAreCountedLoggedAndTold) {
  test::StageBench bench("eeg_lost");
  Acquiring eeg(bench);
  for (int frame = 0; frame < 30; ++frame) {
    if (frame == 10) eeg.source->gap = 48;
    bench.step(*eeg.stage);
    bench.next();
  }
  EXPECT_EQ(bench.previous.eeg.lost_samples, 48);
  EXPECT_EQ(bench.logged("lost_samples").size(), 1u);
  EXPECT_TRUE(bench.toldOf("48 EEG samples lost"));
}

// A trigger box's markers, sent by the amplifier with its data, go into the record's annotations
// (which the recording stage writes) and are counted in the summary.
TEST(EegAcquisitionStage, TheAmplifiersOwnMarkersBecomeTheRecordsAnnotations) {
  test::StageBench bench("eeg_markers");
  Acquiring eeg(bench);
  {
    std::lock_guard lock(eeg.source->mutex);
    eeg.source->markers = {{20, "Stimulus/S  1", 0}, {33, "Response/R  8", 0}};
  }
  bench.step(*eeg.stage);
  ASSERT_EQ(bench.record.annotations.size(), 2u);
  EXPECT_EQ(bench.record.annotations[0].sample, 20);
  EXPECT_EQ(bench.record.annotations[0].text, "Stimulus/S  1");
  EXPECT_EQ(bench.record.annotations[1].text, "Response/R  8");
  bench.next();
  bench.step(*eeg.stage);
  EXPECT_TRUE(bench.record.annotations.empty());  // each once
  nlohmann::json summary;
  eeg.stage->report(summary);
  EXPECT_EQ(summary["eeg"]["source_markers"], 2);
}

TEST(EegAcquisitionStage, ASourcesFaultIsNamedWhenItStartsAndWhenItEnds) {
  test::StageBench bench("eeg_fault");
  Acquiring eeg(bench);
  auto fault = [&](const std::string& text) {
    std::lock_guard lock(eeg.source->mutex);
    eeg.source->fault_text = text;
  };
  for (int frame = 0; frame < 30; ++frame) {
    if (frame == 5) fault("the LSL stream EEG is gone");
    if (frame == 20) fault("");
    bench.step(*eeg.stage);
    if (frame == 10) {
      EXPECT_EQ(bench.record.eeg.fault, "the LSL stream EEG is gone");
    }
    bench.next();
  }
  EXPECT_EQ(bench.previous.eeg.fault, "");
  EXPECT_EQ(bench.logged("eeg_source").size(), 2u);
  EXPECT_TRUE(bench.toldOf("EEG source: the LSL stream EEG is gone"));
  EXPECT_TRUE(bench.toldOf("EEG source delivering again"));
}

// A file at its end: a fault on the record within a second, and the run ends with the reason
// (the recording and the summary whole), never a paradigm waiting for EEG that cannot come.
TEST(EegAcquisitionStage, AFiniteSourceAtItsEndEndsTheRunWithTheReason) {
  test::StageBench bench("eeg_end");
  Acquiring eeg(bench);
  eeg.source->ends_at = 256 * 2;
  int frame = 0;
  for (; frame < 600 && bench.record.end_reason.empty(); ++frame) {
    bench.record.time_s = frame / 60.0;
    bench.step(*eeg.stage);
    if (!bench.record.end_reason.empty()) break;
    bench.next();
  }
  ASSERT_FALSE(bench.record.end_reason.empty());
  EXPECT_EQ(bench.record.end_kind, "fault");
  EXPECT_NE(bench.record.end_reason.find("the EEG source ended"), std::string::npos)
      << bench.record.end_reason;
  EXPECT_NE(bench.record.end_reason.find("(2.0 s of signal)"), std::string::npos)
      << bench.record.end_reason;
  EXPECT_LE(frame / 60.0, 2.0 + 1.0);  // within a second of the last sample
  EXPECT_EQ(bench.record.eeg.fault, bench.record.end_reason);
  nlohmann::json summary;
  eeg.stage->report(summary);
  ASSERT_EQ(summary["eeg"]["faults"].size(), 1u);
}

// One cycle at the host's pace (a live source): the record as the stage left it.
CycleRecord liveCycle(test::StageBench& bench, Acquiring& eeg) {
  bench.record.time_s = bench.clock().frameTime(bench.record.frame);
  bench.record.host_s = bci::hostSeconds();
  bench.step(*eeg.stage);
  CycleRecord stepped = bench.record;
  bench.next();
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  return stepped;
}

// A live source that goes silent: within about a second its silence is the record's fault (the
// paradigm pauses on it), named with the time since its last sample; it clears when samples come
// again.
TEST(EegAcquisitionStage, ALiveSourceThatGoesSilentIsAFaultNamingTheSilence) {
  test::StageBench bench("eeg_silent", Clock::Mode::RealTime);
  Acquiring eeg(bench);
  auto cycle = [&] { return liveCycle(bench, eeg).eeg.fault; };
  for (int i = 0; i < 30; ++i) ASSERT_EQ(cycle(), "");
  eeg.source->hold = true;
  const double from = bci::hostSeconds();
  std::string fault;
  while (fault.empty() && bci::hostSeconds() - from < 5.0) fault = cycle();
  const double after = bci::hostSeconds() - from;
  EXPECT_NE(fault.find("no EEG sample from"), std::string::npos) << fault;
  EXPECT_NE(fault.find("the last arrived at session time"), std::string::npos) << fault;
  EXPECT_GE(after, 0.9);
  EXPECT_LT(after, 3.0);
  EXPECT_TRUE(bench.record.end_reason.empty());  // with an experimenter: a pause, not an end
  eeg.source->hold = false;
  for (int i = 0; i < 50 && !fault.empty(); ++i) fault = cycle();
  EXPECT_EQ(fault, "");
  EXPECT_TRUE(bench.toldOf("EEG source delivering again"));
}

// Without an experimenter nobody can bring a silent source back: the run ends 2.5 s after its
// last sample, with the silence as its reason.
TEST(EegAcquisitionStage, ASilentSourceEndsARunWithoutAnExperimenterWithinThreeSeconds) {
  test::StageBench bench("eeg_silent_headless", Clock::Mode::RealTime);
  Acquiring eeg(bench, "Photodiode", false);
  auto cycle = [&] { return liveCycle(bench, eeg).end_reason; };
  for (int i = 0; i < 30; ++i) ASSERT_EQ(cycle(), "");
  eeg.source->hold = true;
  const double from = bci::hostSeconds();
  std::string ended;
  while (ended.empty() && bci::hostSeconds() - from < 6.0) ended = cycle();
  const double after = bci::hostSeconds() - from;
  EXPECT_NE(ended.find("no EEG sample from"), std::string::npos) << ended;
  EXPECT_NE(ended.find("nobody at the window to bring it back"), std::string::npos) << ended;
  // 1 s to be a silence, 1.5 s more for an outlet restarted at once: 2.5 s of the host's time
  // (a loaded machine's cycles may come later; bench/ reports the figure).
  EXPECT_GE(after, 2.4);
}

TEST(EegAcquisitionStage, APhotodiodeChannelTheSourceLacksIsRefusedNamingTheKey) {
  test::StageBench bench("eeg_no_photodiode");
  try {
    Acquiring eeg(bench, "PD");
    FAIL() << "a photodiode channel the source lacks was taken";
  } catch (const SessionConfigError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("eeg.photodiode_channel = \"PD\""), std::string::npos) << what;
    EXPECT_NE(what.find("Fz, Cz, Photodiode"), std::string::npos) << what;
  }
}

// A live source whose deliveries stop for 0.4 s: the stall is taken in the cycle whose frame the
// presentation stage stamped inside it, and that flash's stamp is marked uncertain.
TEST(EegAcquisitionStage, AFlashStampedInTheCycleAStallIsTakenIsMarkedUncertain) {
  test::StageBench bench("eeg_stall", Clock::Mode::RealTime);
  Acquiring eeg(bench);
  auto cycle = [&] {
    bench.record.time_s = bench.clock().frameTime(bench.record.frame);
    bench.step(*eeg.stage);
    bench.next();
  };
  for (int i = 0; i < 50; ++i) {
    cycle();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const double held_from = bci::hostSeconds();
  eeg.source->hold = true;
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  eeg.source->hold = false;
  // The held-back blocks arrive at once, on the acquisition's thread; each cycle until the stall
  // is taken stamps a flash presented while the deliveries were held.
  std::int64_t marked_sample = -1;
  bool marked = false;
  for (int i = 0; i < 400 && marked_sample < 0; ++i) {
    const std::int64_t sample = 4000 + i;
    bench.record.presentation.shown = true;
    bench.record.presentation.host_s = held_from + 0.2;
    bench.record.presentation.onsets.push_back({Flash{1, true, false, true, 1}, sample});
    bench.record.time_s = bench.clock().frameTime(bench.record.frame);
    bench.step(*eeg.stage);
    if (!bench.record.eeg.stalls.empty()) {
      marked_sample = sample;
      for (const bci::Annotation& a : bench.record.annotations)
        marked |= a.sample == sample && a.text == "stamp uncertain: EEG delivery stalled";
    }
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_GE(marked_sample, 0) << "no stall was taken";
  EXPECT_TRUE(marked);
  EXPECT_TRUE(bench.toldOf("EEG delivery stalled"));
  const auto logged = bench.logged("eeg_stall");
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_GE(logged[0]["uncertain_flashes"].get<int>(), 1);
}

}  // namespace
}  // namespace arbci::session
