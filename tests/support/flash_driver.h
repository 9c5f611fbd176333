// Cycles at 60 Hz that flash P300-style on hand-built records, with a simulated subject's EEG
// answering them: each cycle's record gets the flashes first shown (stamped at the frame's sample)
// and the EEG blocks generated up to its time, as the presentation and acquisition stages would
// write them. For the tests of the stages that read those parts (P300, ErrP).
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include "arbci/bci/paradigm_layout.h"
#include "arbci/bci/sample_clock.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/session/cycle.h"
#include "arbci/session/stage.h"
#include "support/stage_bench.h"

namespace arbci::test {

class FlashDriver {
 public:
  // `stimuli` objects, flashed every 11 frames (180 ms at 60 Hz), 4 frames each.
  FlashDriver(StageBench& bench, int stimuli, std::uint64_t seed = 3)
      : bench_(bench), stimuli_(stimuli), random_(seed) {
    bci::SimulatedSubjectConfig config;
    config.seed = seed;
    clock_ = std::make_shared<bci::ManualClock>();
    subject_ = std::make_unique<bci::SimulatedSubject>(config, clock_);
  }
  const bci::SignalInfo& info() const { return subject_->info(); }
  bci::SimulatedSubject& subject() { return *subject_; }
  // From now on the subject attends none of the stimuli (the selections still name a target).
  void lookAway() { attentive_ = false; }
  // A DC-coupled amplifier: every channel offset by `offset_uv` (alternating in sign) plus a
  // drift of `drift_uv_per_s` from sample 0.
  void amplifierOffset(double offset_uv, double drift_uv_per_s) {
    offset_uv_ = offset_uv;
    drift_uv_per_s_ = drift_uv_per_s;
  }
  // Every block delivered so far and every flash shown, as an offline analysis would read them.
  const std::vector<bci::Block>& delivered() const { return delivered_; }
  const std::vector<bci::StimulusEvent>& shown() const { return shown_; }

  // One selection of `sequences` sequences (each code once per sequence, in random order) with
  // `target` attended; `cued`: a calibration selection (its target announced); `retake_of`: it
  // replaces an interrupted one. Runs `tail_s` more after the last flash (for its epoch).
  // `labelled`: the code the flashes are labelled as attended, when not `target` (a wrong label,
  // for a stage that must not read them).
  void selection(session::Stage& stage, int number, int target, bool cued, int sequences,
                 std::optional<int> retake_of = std::nullopt, double tail_s = 1.0,
                 std::optional<int> labelled = std::nullopt) {
    session::SelectionStart start{number,
                                  true,
                                  bci::ParadigmLayout::single(stimuli_, 11.0 / 60.0),
                                  {target},
                                  cued ? std::optional<int>(target) : std::nullopt,
                                  retake_of};
    subject_->attend(attentive_ ? std::set<int>{target} : std::set<int>{});
    bench_.previous.paradigm.selection_started = start;
    std::vector<int> order;
    for (int s = 0; s < sequences; ++s) {
      std::vector<int> codes(static_cast<size_t>(stimuli_));
      for (int k = 0; k < stimuli_; ++k) codes[static_cast<size_t>(k)] = k + 1;
      std::shuffle(codes.begin(), codes.end(), random_);
      order.insert(order.end(), codes.begin(), codes.end());
    }
    const int tail = static_cast<int>(tail_s * 60.0);
    for (size_t f = 0; f < order.size() * 11 + static_cast<size_t>(tail); ++f) {
      if (f % 11 == 0 && f / 11 < order.size()) {
        const int code = order[f / 11];
        flash(number, code, code == labelled.value_or(target));
      }
      step(stage);
    }
  }
  // A flash first shown on this cycle's frame.
  void flash(int selection, int code, bool target) {
    const std::int64_t sample = sampleNow();
    bench_.record.presentation.shown = true;
    bench_.record.presentation.sample = sample;
    bench_.record.presentation.onsets.push_back(
        {session::Flash{code, true, target, true, selection}, sample});
    subject_->present({sample, code, target, 15, true});
    shown_.push_back({sample, code, target, 15, true});
  }
  // A feedback first shown on this cycle's frame.
  void feedback(const std::set<int>& codes, std::optional<bool> error) {
    bench_.record.presentation.shown = true;
    bench_.record.presentation.sample = sampleNow();
    bench_.record.presentation.feedback = session::FeedbackShown{codes, true, error};
    subject_->feedback(sampleNow(), codes);
  }
  // The cycle with the EEG generated up to its time; then the next.
  void step(session::Stage& stage) {
    const double t = bench_.record.frame / 60.0;
    clock_->advanceTo(t);
    for (bci::Block& block : subject_->poll(1000)) {
      for (int c = 0; c < block.channels; ++c) {
        for (int i = 0; i < block.samples; ++i) {
          const double t_s = static_cast<double>(block.first_sample + i) / info().rate_hz;
          block.at(c, i) +=
              static_cast<float>((c % 2 ? -offset_uv_ : offset_uv_) + drift_uv_per_s_ * t_s);
        }
      }
      delivered_.push_back(block);
      bench_.record.eeg.eeg_blocks.push_back(block);
      bench_.record.eeg.blocks.push_back(std::move(block));
    }
    bench_.step(stage);
    bench_.next();
  }
  void idle(session::Stage& stage, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 60.0); ++i) step(stage);
  }

 private:
  std::int64_t sampleNow() const {
    return static_cast<std::int64_t>(std::ceil(bench_.record.frame / 60.0 * info().rate_hz - 1e-9));
  }
  StageBench& bench_;
  int stimuli_;
  std::mt19937_64 random_;
  bool attentive_ = true;
  double offset_uv_ = 0.0, drift_uv_per_s_ = 0.0;
  std::vector<bci::Block> delivered_;
  std::vector<bci::StimulusEvent> shown_;
  std::shared_ptr<bci::ManualClock> clock_;
  std::unique_ptr<bci::SimulatedSubject> subject_;
};

}  // namespace arbci::test
