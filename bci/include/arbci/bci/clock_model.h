// Maps host time to the EEG sample clock. Each delivery from an amplifier is stamped with the host
// time it arrived; a least-squares fit of arrival time against sample index, over a sliding window,
// gives the amplifier's true rate (its drift against the host clock, in ppm) and the arrival
// jitter. Arrivals can only be late (buffering, transport), never early, so the fitted line is
// moved down to the earliest arrivals (a low quantile of the residuals): a block's last sample was
// taken no later than the lower envelope says. A known, constant delivery latency (from
// `arbci timing-check`, or a simulated source's own) is subtracted before fitting.
//
// Stalls and bursts. Only the newest block of a delivery says when the amplifier got there: the
// older blocks in the same delivery (a backlog after a stall, or at start-up) arrived late by
// however long they waited, so when several blocks share one arrival instant only the newest is
// kept. An arrival later than the envelope by more than `kLateLimitS` (a delivery held up, a
// process paused) is not fitted: it is reported to the caller as a stall. The drift the fit may
// take is bounded (`kMaxDriftPpm`); a fit that wants more, or whose uncertainty is above 5 ppm,
// is reported as unreliable rather than believed.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

namespace arbci::bci {

class ClockModel {
 public:
  // The most drift a fit may take, either way: real amplifier crystals stay within about 100 ppm;
  // a fit beyond this is the data disagreeing (a wrong nominal rate, stalls), and says so.
  static constexpr double kMaxDriftPpm = 500.0;
  // An arrival later than the lower envelope by more than this is a stall, not jitter: USB and
  // network deliveries arrive within a few milliseconds, bursts of a few blocks within ~200 ms.
  static constexpr double kLateLimitS = 0.25;
  // Drift is reported as reliable once its uncertainty (one standard error) is below this: three
  // standard errors within 15 ppm, so a reliable drift is within 20 ppm of the truth.
  static constexpr double kReliableDriftPpm = 5.0;

  // What one observation came to.
  struct Observation {
    double late_s = 0.0;  // how much later than the envelope it arrived (before fitting it)
    bool stall = false;   // later than kLateLimitS: not fitted
    bool refit = false;   // the model started again on this arrival (see observe)
  };

  // `nominal_rate_hz`: the rate the amplifier claims; `window_s`: how much history the fit uses.
  // Throws std::invalid_argument for a rate or window that is not positive.
  explicit ClockModel(double nominal_rate_hz, double window_s = 120.0, double latency_s = 0.0);

  // A block whose samples end before `end_sample` (exclusive) arrived at `host_s` (seconds of the
  // host clock: hostSeconds(), or the simulated clock of a headless run). Blocks of one delivery
  // share `host_s`; only the newest of them is kept. When every arrival for `window_s / 12` has
  // been a stall, the delivery path has changed for good (a reconnect, a new buffer): the model
  // starts again from the arrivals since.
  Observation observe(std::int64_t end_sample, double host_s);
  // The samples stepped over a gap (lost, their count taken from the other side's stamps or from
  // the time away): a count off by a sample or two is a step in the line that would bend the
  // drift for the whole window, so the fit starts again from the next arrival (the drift is
  // unreliable until the new span is long enough). The mapping holds meanwhile.
  void startAgain();

  // True once two deliveries have been observed (before that, the nominal rate).
  bool fitted() const { return points_.size() >= 2; }
  bool empty() const { return points_.empty(); }
  // The sample index (fractional) taken at host time `host_s`.
  double sampleAt(double host_s) const;
  // The first whole sample taken at or after `host_s`: what a stimulus presented then is stamped.
  std::int64_t firstSampleAtOrAfter(double host_s) const;

  // (fitted rate / nominal rate - 1) * 1e6: positive when the amplifier's clock runs fast.
  double driftPpm() const;
  // One standard error of driftPpm() (from the residuals about the fit and the span it covers).
  double driftUncertaintyPpm() const { return drift_se_ppm_; }
  // The fit wanted more than kMaxDriftPpm and was held at the bound.
  bool driftAtBound() const { return at_bound_; }
  // Neither at the bound nor uncertain by more than kReliableDriftPpm.
  bool driftReliable() const {
    return fitted() && !at_bound_ && drift_se_ppm_ <= kReliableDriftPpm;
  }
  double rateHz() const;
  // RMS of the arrival times about the fitted line, in seconds (stalls excluded).
  double jitterS() const { return jitter_s_; }

 private:
  struct Point {
    double sample;  // relative to the anchor
    double host;    // relative to the anchor
  };
  void refit();
  void fitLine(const std::deque<Point>& points, const std::vector<bool>& keep);
  void restart();

  double nominal_rate_;
  double window_s_;
  double latency_s_;
  std::deque<Point> points_;
  bool anchored_ = false;
  double anchor_sample_ = 0.0, anchor_host_ = 0.0;
  // host = intercept_ + slope_ * sample, both relative to the anchor.
  double slope_ = 0.0, intercept_ = 0.0;
  double jitter_s_ = 0.0;
  double drift_se_ppm_ = 0.0;
  bool at_bound_ = false;
  std::int64_t observed_ = 0;
  // The delivery the newest point came from, and whether it was kept.
  double last_arrival_ = 0.0;
  bool last_kept_ = false;
  bool have_arrival_ = false;
  // Stalls since the last kept arrival: when they have lasted long enough, the model restarts.
  std::deque<Point> stalled_;
};

}  // namespace arbci::bci
