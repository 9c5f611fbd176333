#include "arbci/session/stimulus_timing.h"

#include <algorithm>

#include "arbci/session/cycle_timing.h"

namespace arbci::session {
namespace {

// A statistic of `values` in ms (they are in samples), or null when there are none.
nlohmann::json inMs(const std::vector<double>& values, double Percentiles::*statistic,
                    double samples_to_ms) {
  if (values.empty()) return nullptr;
  return percentiles(values).*statistic * samples_to_ms;
}

// The 5th percentile (nearest rank) in ms, or null.
nlohmann::json fifthPercentile(std::vector<double> values, double samples_to_ms) {
  if (values.empty()) return nullptr;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(0.05 * (values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at * samples_to_ms;
}

}  // namespace

StimulusTiming::StimulusTiming(const bci::ParadigmSettings& paradigm, double eeg_rate_hz)
    : paradigm_(paradigm), rate_hz_(eeg_rate_hz) {}

StimulusTiming::Frame StimulusTiming::presented(double due_s, double presented_s,
                                                std::int64_t sample, const std::set<int>& lit,
                                                const std::vector<int>& first_shown) {
  Frame frame;
  const double period = 1.0 / paradigm_.display_hz;
  ++frames_;
  // Late: later than one frame period after it was due (a microsecond's grace for arithmetic).
  frame.late = presented_s > due_s + period + 1e-6;
  late_frames_ += frame.late;
  if (last_presented_) {
    frame_intervals_s_.push_back(presented_s - *last_presented_);
    if (frame_intervals_s_.size() > 600)
      frame_intervals_s_.erase(frame_intervals_s_.begin(), frame_intervals_s_.begin() + 300);
  }
  last_presented_ = presented_s;

  // Flashes no longer shown have ended on this frame.
  for (auto it = active_.begin(); it != active_.end();) {
    if (lit.count(it->first)) {
      ++it;
      continue;
    }
    const auto duration = static_cast<int>(sample - it->second.onset_sample);
    frame.ended.push_back({it->second.onset_sample, duration});
    last_end_sample_ = sample;
    duration_samples_.push_back(duration);
    it = active_.erase(it);
  }
  // Rules a P300 paradigm must keep: one stimulus at a time, a dark frame before each onset.
  for (size_t k = 0; k < first_shown.size(); ++k) {
    overlapped_ += !active_.empty() || k > 0;
    gapless_ += last_patch_lit_;
    if (last_end_sample_) gap_samples_.push_back(static_cast<double>(sample - *last_end_sample_));
  }
  for (int code : first_shown) {
    frame.onsets.push_back({code, sample});
    active_.emplace_back(code, Active{sample});
    if (!selection_onsets_.empty())
      soa_samples_.push_back(static_cast<double>(sample - selection_onsets_.back()));
    selection_onsets_.push_back(sample);
  }
  frame.patch_lit = !lit.empty();
  last_patch_lit_ = frame.patch_lit;
  return frame;
}

void StimulusTiming::startSelection() {
  selection_onsets_.clear();
  selection_interrupted_s_ = 0.0;
}

void StimulusTiming::interrupted(double seconds) {
  // Before the first onset the span has not begun: nothing to take out of it.
  if (!selection_onsets_.empty()) selection_interrupted_s_ += seconds;
}

double StimulusTiming::medianSoaS() const {
  if (soa_samples_.empty()) return paradigm_.soaSeconds();
  return percentiles(soa_samples_).p50 / rate_hz_;
}

double StimulusTiming::selectionSeconds() const {
  if (selection_onsets_.empty()) return 0.0;
  const double span =
      static_cast<double>(selection_onsets_.back() - selection_onsets_.front()) / rate_hz_;
  return std::max(0.0, span - selection_interrupted_s_) + medianSoaS();
}

std::optional<double> StimulusTiming::medianFrameIntervalMs() const {
  if (frame_intervals_s_.size() < 60) return std::nullopt;
  return 1000.0 * percentiles(frame_intervals_s_).p50;
}

bool StimulusTiming::displayTooSlow() const {
  const auto median = medianFrameIntervalMs();
  return median && tooSlow(*median / 1000.0, paradigm_.display_hz);
}

nlohmann::json StimulusTiming::summary() const {
  const double to_ms = 1000.0 / rate_hz_;
  const auto frame_median = medianFrameIntervalMs();
  // An SOA over the paradigm's (in whole frames) by more than half a frame: the schedule slipped.
  const double soa_limit = (paradigm_.soaSeconds() + 0.5 / paradigm_.display_hz) * rate_hz_;
  const auto slipped = std::count_if(soa_samples_.begin(), soa_samples_.end(),
                                     [&](double soa) { return soa > soa_limit; });
  auto least = [&](const std::vector<double>& v) {
    return v.empty() ? nlohmann::json(nullptr)
                     : nlohmann::json(*std::min_element(v.begin(), v.end()) * to_ms);
  };
  return {
      {"soa_ms",
       {{"configured", paradigm_.flash_ms + paradigm_.isi_ms},
        {"frames", paradigm_.soaSeconds() * 1000.0},
        {"median", inMs(soa_samples_, &Percentiles::p50, to_ms)},
        {"p95", inMs(soa_samples_, &Percentiles::p95, to_ms)},
        {"p5", fifthPercentile(soa_samples_, to_ms)},
        {"min", least(soa_samples_)},
        {"slipped", slipped},
        {"count", soa_samples_.size()}}},
      {"flash_rules",
       {{"overlapped", overlapped_},
        {"gapless", gapless_},
        {"min_gap_ms", least(gap_samples_)},
        {"gap_ms_configured", (paradigm_.soaSeconds() - paradigm_.flashSeconds()) * 1000.0}}},
      {"flash_ms",
       {{"configured", paradigm_.flash_ms},
        {"median", inMs(duration_samples_, &Percentiles::p50, to_ms)},
        {"count", duration_samples_.size()}}},
      {"display",
       {{"configured_hz", paradigm_.display_hz},
        {"median_frame_ms", frame_median ? nlohmann::json(*frame_median) : nlohmann::json(nullptr)},
        {"holds_rate", !displayTooSlow()}}},
      {"frames", frames_},
      {"late_frames", late_frames_},
  };
}

}  // namespace arbci::session
