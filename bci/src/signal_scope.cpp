#include "arbci/bci/signal_scope.h"

#include <algorithm>
#include <cmath>

namespace arbci::bci {

SignalScope::SignalScope(const SignalInfo& info, double seconds,
                         const FilterSettings& display_filter,
                         std::optional<QualityThresholds> thresholds)
    : info_(info),
      capacity_(std::max(1, static_cast<int>(std::lround(seconds * info.rate_hz)))),
      thresholds_(thresholds),
      raw_(static_cast<size_t>(info.channelCount()) * static_cast<size_t>(capacity_), 0.0f),
      filtered_(raw_.size(), 0.0f) {
  // The display filter without the common average: a bad channel's quality stays its own.
  FilterSettings settings = display_filter;
  settings.common_average = false;
  filter_ = std::make_unique<FilterChain>(settings, info_);
}

void SignalScope::append(const Block& block) {
  if (block.channels != info_.channelCount() || block.samples <= 0) return;
  if (!started_) {
    end_ = assessed_at_ = first_ = block.first_sample;  // the acquisition's sample indices
    started_ = true;
  }
  // Samples lost before this block are shown as zeros, where they were.
  for (std::int64_t gap = std::min<std::int64_t>(block.first_sample - end_, capacity_); gap > 0;
       --gap, ++end_) {
    for (int c = 0; c < block.channels; ++c) {
      const size_t at = static_cast<size_t>(c) * static_cast<size_t>(capacity_) +
                        static_cast<size_t>(end_ % capacity_);
      raw_[at] = filtered_[at] = 0.0f;
    }
  }
  end_ = std::max(end_, block.first_sample);
  Block filtered = block;
  filter_->process(filtered);
  for (int s = 0; s < block.samples; ++s) {
    const size_t slot = static_cast<size_t>((end_ + s) % capacity_);
    for (int c = 0; c < block.channels; ++c) {
      const size_t at = static_cast<size_t>(c) * static_cast<size_t>(capacity_) + slot;
      raw_[at] = block.at(c, s);
      filtered_[at] = filtered.at(c, s);
    }
  }
  end_ += block.samples;
  while (!stimuli_.empty() && stimuli_.front() < end_ - capacity_) stimuli_.pop_front();
  // Twice a second, over the last two seconds.
  if (thresholds_ && end_ - assessed_at_ >= static_cast<std::int64_t>(info_.rate_hz / 2.0))
    assess();
}

void SignalScope::markStimulus(std::int64_t sample) {
  stimuli_.push_back(sample);
}

float SignalScope::at(int channel, int k, bool filtered) const {
  if (k < 0 || k >= capacity_ || k >= end_ - first_) return 0.0f;
  const size_t slot = static_cast<size_t>((end_ - 1 - k) % capacity_);
  const auto& ring = filtered ? filtered_ : raw_;
  return ring[static_cast<size_t>(channel) * static_cast<size_t>(capacity_) + slot];
}

void SignalScope::copyLast(int channel, int n, bool filtered, std::vector<float>& out) const {
  n = std::clamp(n, 0, capacity_);
  out.assign(static_cast<size_t>(n), 0.0f);
  const int have = static_cast<int>(std::min<std::int64_t>(n, end_ - first_));
  const float* ring = (filtered ? filtered_ : raw_).data() +
                      static_cast<size_t>(channel) * static_cast<size_t>(capacity_);
  // The newest `have` samples end at slot end_ % capacity_: at most two runs of the ring.
  const int start = static_cast<int>((end_ - have) % capacity_);
  const int first_run = std::min(have, capacity_ - start);
  float* to = out.data() + (n - have);
  std::copy(ring + start, ring + start + first_run, to);
  std::copy(ring, ring + (have - first_run), to + first_run);
}

void SignalScope::assess() {
  assessed_at_ = end_;
  const int n = std::min(capacity_, static_cast<int>(std::lround(2.0 * info_.rate_hz)));
  if (end_ - first_ < n) return;
  quality_.resize(static_cast<size_t>(info_.channelCount()));
  std::vector<float> window(static_cast<size_t>(n));
  for (int c = 0; c < info_.channelCount(); ++c) {
    for (int k = 0; k < n; ++k) window[static_cast<size_t>(k)] = at(c, n - 1 - k, false);
    quality_[static_cast<size_t>(c)] = assessSignal(window.data(), n, info_.rate_hz, *thresholds_);
  }
}

}  // namespace arbci::bci
