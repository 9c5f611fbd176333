#include "arbci/ui/window_state.h"

#include "arbci/session/cycle_timing.h"

namespace arbci::ui {
namespace {
// The Session panel's plot: about five seconds at 60 Hz.
constexpr size_t kRecentCycles = 300;
// Percentiles over every cycle so far are refreshed this often (cycles), not every frame.
constexpr size_t kTimingEvery = 30;
// The EEG panel's longest time base.
constexpr double kScopeSeconds = 10.0;

StageTiming timingOf(const std::string& stage, const std::vector<double>& values) {
  const session::Percentiles p = session::percentiles(values);
  return {stage, p.p50, p.p90, p.p99, p.max, values.empty() ? 0.0 : values.back()};
}
}  // namespace

void WindowState::ingest(const session::CycleRecord& record,
                         const session::SessionConfig& settings) {
  if (!scope_ && record.eeg.info)
    scope_.emplace(*record.eeg.info, kScopeSeconds, settings.classifier.pipeline.filter);
  if (scope_) {
    for (const bci::Block& block : record.eeg.blocks) scope_->append(block);
    for (const session::Presentation::Onset& onset : record.presentation.onsets)
      scope_->markStimulus(onset.sample);
  }
  if (!record.stage_ms.empty()) refreshTiming(record);
  if (describe_run_ && described_ != record.labels) {
    // Once per change, not per frame: the account may look through the BIDS dataset's folders.
    described_ = record.labels;
    run_target_ = describe_run_(record.labels);
  }
}

void WindowState::refreshTiming(const session::CycleRecord& record) {
  for (const auto& [stage, ms] : record.stage_ms) stage_ms_[stage].push_back(ms);
  total_ms_.push_back(record.compute_ms);
  recent_.push_back(static_cast<float>(record.compute_ms));
  if (recent_.size() > kRecentCycles) recent_.erase(recent_.begin());
  if (total_ms_.size() % kTimingEvery != 1) {
    // Between refreshes only the last cycle's times move.
    for (StageTiming& t : timing_) {
      const auto found = record.stage_ms.find(t.stage);
      t.last_ms = t.stage == "total"               ? record.compute_ms
                  : found != record.stage_ms.end() ? found->second
                                                   : 0.0;
    }
    return;
  }
  timing_.clear();
  for (const auto& [stage, values] : stage_ms_) timing_.push_back(timingOf(stage, values));
  timing_.push_back(timingOf("total", total_ms_));
}

double WindowState::cycleP50Ms() const {
  return timing_.empty() ? 0.0 : timing_.back().p50_ms;
}

}  // namespace arbci::ui
