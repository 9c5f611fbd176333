// The last seconds of every channel as acquired, for the experimenter's EEG view: raw and through
// a display filter, the stimulus onsets among them, and, where given thresholds, each channel's
// quality (signal_quality.h) re-assessed twice a second over its last two seconds (the session's
// SignalQualityStage grades; the view shows its grades). Fed block by block on the session's
// thread; read between blocks.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/filters.h"
#include "arbci/bci/signal.h"
#include "arbci/bci/signal_quality.h"

namespace arbci::bci {

class SignalScope {
 public:
  // `info`: every channel as acquired; `display_filter`: what the filtered view runs (the
  // session's online filter: the experimenter sees what the classifier sees); `thresholds`: what
  // quality() grades against, none: no grading.
  SignalScope(const SignalInfo& info, double seconds, const FilterSettings& display_filter,
              std::optional<QualityThresholds> thresholds = std::nullopt);
  void append(const Block& block);
  void markStimulus(std::int64_t sample);

  const SignalInfo& info() const { return info_; }
  int capacity() const { return capacity_; }       // samples kept per channel
  std::int64_t endSample() const { return end_; }  // one past the newest sample
  // Sample `k` samples before the newest (0: the newest) of `channel`, raw or filtered; 0 before
  // the first sample.
  float at(int channel, int k, bool filtered) const;
  // The last `n` samples of `channel` (n <= capacity), oldest first, into `out`; zeros before
  // the first sample.
  void copyLast(int channel, int n, bool filtered, std::vector<float>& out) const;
  // Onsets (sample indices) still in view, oldest first.
  const std::deque<std::int64_t>& stimuli() const { return stimuli_; }
  // One per channel; empty until two seconds have been seen, or without thresholds.
  const std::vector<SignalQuality>& quality() const { return quality_; }

 private:
  void assess();
  SignalInfo info_;
  int capacity_;
  std::optional<QualityThresholds> thresholds_;
  std::unique_ptr<FilterChain> filter_;
  std::vector<float> raw_, filtered_;  // [channel][capacity], a ring ending at end_
  std::int64_t first_ = 0, end_ = 0, assessed_at_ = 0;
  bool started_ = false;
  std::deque<std::int64_t> stimuli_;
  std::vector<SignalQuality> quality_;
};

}  // namespace arbci::bci
