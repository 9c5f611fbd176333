#include "arbci/bci/clock_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace arbci::bci {

namespace {
// The line is moved to this quantile of the residuals: low enough to follow the earliest
// arrivals, high enough that one early outlier (a host clock step) does not move it.
constexpr double kEnvelopeQuantile = 0.05;
// Refitting every delivery costs a sort of the window; every few is as good.
constexpr std::int64_t kRefitEvery = 4;
// Below this many points the fit is too young to call an arrival a stall.
constexpr size_t kMinPointsToJudge = 16;
// The second pass of a fit leaves out arrivals this many robust standard deviations (or at least
// this many seconds) above the median residual: late deliveries that are not stalls yet.
constexpr double kOutlierSigmas = 4.0;
constexpr double kOutlierFloorS = 0.002;

double quantile(std::vector<double> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}
}  // namespace

ClockModel::ClockModel(double nominal_rate_hz, double window_s, double latency_s)
    : nominal_rate_(nominal_rate_hz), window_s_(window_s), latency_s_(latency_s) {
  if (!(nominal_rate_hz > 0.0))
    throw std::invalid_argument("clock model: the sampling rate must be positive");
  if (!(window_s > 0.0)) throw std::invalid_argument("clock model: the window must be positive");
  slope_ = 1.0 / nominal_rate_hz;
}

ClockModel::Observation ClockModel::observe(std::int64_t end_sample, double host_s) {
  // Sample n covers the period from n / rate: a block is complete once the period of its last
  // sample is over, i.e. at the start of sample `end_sample`.
  const double sample = static_cast<double>(end_sample);
  const double host = host_s - latency_s_;
  if (!anchored_) {
    anchored_ = true;
    anchor_sample_ = sample;
    anchor_host_ = host;
  }
  const Point p{sample - anchor_sample_, host - anchor_host_};
  // A later block of the same delivery: it replaces the older one (whose arrival only bounds it).
  const bool same_delivery = have_arrival_ && host_s == last_arrival_;
  if (same_delivery) {
    if (last_kept_ && !points_.empty()) {
      points_.pop_back();
    } else if (!last_kept_ && !stalled_.empty()) {
      stalled_.pop_back();
    }
  }
  have_arrival_ = true;
  last_arrival_ = host_s;
  ++observed_;

  Observation out;
  if (points_.size() >= kMinPointsToJudge) {
    out.late_s = p.host - (intercept_ + slope_ * p.sample);
    if (out.late_s > kLateLimitS) {
      out.stall = true;
      last_kept_ = false;
      stalled_.push_back(p);
      // Nothing but stalls for a twelfth of the window: the delivery path changed; start again.
      if (stalled_.back().sample - stalled_.front().sample > window_s_ * nominal_rate_ / 12.0) {
        restart();
        out.refit = true;
      }
      return out;
    }
  }
  stalled_.clear();
  last_kept_ = true;
  points_.push_back(p);
  const double oldest_allowed = points_.back().sample - window_s_ * nominal_rate_;
  while (points_.size() > 2 && points_.front().sample < oldest_allowed) points_.pop_front();
  if (points_.size() < kMinPointsToJudge || observed_ % kRefitEvery == 0 || same_delivery) refit();
  return out;
}

void ClockModel::startAgain() {
  points_.clear();
  stalled_.clear();
  have_arrival_ = false;
  drift_se_ppm_ = 0.0;
}

void ClockModel::restart() {
  points_ = std::move(stalled_);
  stalled_.clear();
  last_kept_ = true;
  refit();
}

void ClockModel::fitLine(const std::deque<Point>& points, const std::vector<bool>& keep) {
  // Least squares about the means (well conditioned however long the session runs).
  double mean_s = 0.0, mean_h = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!keep[i]) continue;
    mean_s += points[i].sample;
    mean_h += points[i].host;
    ++n;
  }
  if (n < 2) return;
  mean_s /= static_cast<double>(n);
  mean_h /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!keep[i]) continue;
    sxx += (points[i].sample - mean_s) * (points[i].sample - mean_s);
    sxy += (points[i].sample - mean_s) * (points[i].host - mean_h);
  }
  if (sxx <= 0.0) return;
  const double nominal_slope = 1.0 / nominal_rate_;
  const double fitted = sxy / sxx;
  // slope is seconds a sample: a fast clock (positive drift) has a smaller slope.
  const double lowest = nominal_slope / (1.0 + kMaxDriftPpm * 1e-6);
  const double highest = nominal_slope / (1.0 - kMaxDriftPpm * 1e-6);
  slope_ = std::clamp(fitted, lowest, highest);
  at_bound_ = fitted < lowest || fitted > highest;
  intercept_ = mean_h - slope_ * mean_s;
  double sum_squares = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!keep[i]) continue;
    const double r = points[i].host - (intercept_ + slope_ * points[i].sample);
    sum_squares += r * r;
  }
  jitter_s_ = std::sqrt(sum_squares / static_cast<double>(n));
  // The slope's standard error, as a fraction of the slope: the drift's uncertainty.
  const double se = n > 2 ? std::sqrt(sum_squares / static_cast<double>(n - 2) / sxx) : slope_;
  drift_se_ppm_ = se / slope_ * 1e6;
}

void ClockModel::refit() {
  const size_t n = points_.size();
  if (n == 0) return;
  if (n == 1) {
    slope_ = 1.0 / nominal_rate_;
    intercept_ = points_.front().host - slope_ * points_.front().sample;
    jitter_s_ = 0.0;
    drift_se_ppm_ = 0.0;
    at_bound_ = false;
    return;
  }
  std::vector<bool> keep(n, true);
  fitLine(points_, keep);
  std::vector<double> residuals(n);
  for (size_t i = 0; i < n; ++i)
    residuals[i] = points_[i].host - (intercept_ + slope_ * points_[i].sample);
  // Second pass without the late outliers (a held-up delivery short of a stall): they would tilt
  // the line for as long as they stay in the window.
  if (n >= kMinPointsToJudge) {
    const double median = quantile(residuals, 0.5);
    std::vector<double> deviations(n);
    for (size_t i = 0; i < n; ++i) deviations[i] = std::abs(residuals[i] - median);
    const double sigma = 1.4826 * quantile(deviations, 0.5);
    const double limit = median + std::max(kOutlierSigmas * sigma, kOutlierFloorS);
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i) kept += keep[i] = residuals[i] <= limit;
    if (kept >= 2 && kept < n) {
      fitLine(points_, keep);
      for (size_t i = 0; i < n; ++i)
        residuals[i] = points_[i].host - (intercept_ + slope_ * points_[i].sample);
    }
  }
  intercept_ += quantile(residuals, kEnvelopeQuantile);
}

double ClockModel::sampleAt(double host_s) const {
  if (points_.empty()) return host_s * nominal_rate_;
  return anchor_sample_ + (host_s - anchor_host_ - intercept_) / slope_;
}

std::int64_t ClockModel::firstSampleAtOrAfter(double host_s) const {
  // A tolerance far below a sample keeps an exact instant (a simulated frame) on its own sample.
  return static_cast<std::int64_t>(std::ceil(sampleAt(host_s) - 1e-6));
}

double ClockModel::rateHz() const {
  return 1.0 / slope_;
}

double ClockModel::driftPpm() const {
  return (rateHz() / nominal_rate_ - 1.0) * 1e6;
}

}  // namespace arbci::bci
