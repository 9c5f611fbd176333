// Maps host time to the EEG sample clock. Each block an amplifier delivers is stamped with the
// host time it arrived; an online least-squares fit of arrival time against sample index, over a
// sliding window, gives the amplifier's true rate (its drift against the host clock, in ppm) and
// the arrival jitter. Arrivals can only be late (buffering, transport), never early, so the fitted
// line is moved down to the earliest arrivals (a low quantile of the residuals): a block's last
// sample was taken no later than the lower envelope says. A known, constant delivery latency (from
// `arbci timing-check`, or a simulated source's own) is subtracted before fitting.
#pragma once

#include <cstdint>
#include <deque>

namespace arbci::bci {

class ClockModel {
 public:
  // `nominal_rate_hz`: the rate the amplifier claims; `window_s`: how much history the fit uses.
  // Throws std::invalid_argument for a rate or window that is not positive.
  explicit ClockModel(double nominal_rate_hz, double window_s = 120.0, double latency_s = 0.0);

  // A block whose samples end before `end_sample` (exclusive) arrived at `host_s` (seconds of the
  // host clock: hostSeconds(), or the simulated clock of a headless run).
  void observe(std::int64_t end_sample, double host_s);

  // True once two blocks have been observed (before that, the nominal rate from the first block).
  bool fitted() const { return points_.size() >= 2; }
  bool empty() const { return points_.empty(); }
  // The sample index (fractional) taken at host time `host_s`.
  double sampleAt(double host_s) const;
  // The first whole sample taken at or after `host_s`: what a stimulus presented then is stamped.
  std::int64_t firstSampleAtOrAfter(double host_s) const;

  // (fitted rate / nominal rate - 1) * 1e6: positive when the amplifier's clock runs fast.
  double driftPpm() const;
  double rateHz() const;
  // RMS of the arrival times about the fitted line, in seconds.
  double jitterS() const { return jitter_s_; }

 private:
  struct Point {
    double sample;  // relative to the anchor
    double host;    // relative to the anchor
  };
  void refit();

  double nominal_rate_;
  double window_s_;
  double latency_s_;
  std::deque<Point> points_;
  bool anchored_ = false;
  double anchor_sample_ = 0.0, anchor_host_ = 0.0;
  // host = intercept_ + slope_ * sample, both relative to the anchor.
  double slope_ = 0.0, intercept_ = 0.0;
  double jitter_s_ = 0.0;
  std::int64_t observed_ = 0;
};

}  // namespace arbci::bci
