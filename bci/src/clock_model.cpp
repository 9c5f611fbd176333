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
// Refitting every block costs a sort of the window; every few blocks is as good.
constexpr std::int64_t kRefitEvery = 4;
}  // namespace

ClockModel::ClockModel(double nominal_rate_hz, double window_s, double latency_s)
    : nominal_rate_(nominal_rate_hz), window_s_(window_s), latency_s_(latency_s) {
  if (!(nominal_rate_hz > 0.0))
    throw std::invalid_argument("clock model: the sampling rate must be positive");
  if (!(window_s > 0.0)) throw std::invalid_argument("clock model: the window must be positive");
  slope_ = 1.0 / nominal_rate_hz;
}

void ClockModel::observe(std::int64_t end_sample, double host_s) {
  // Sample n covers the period from n / rate: a block is complete once the period of its last
  // sample is over, i.e. at the start of sample `end_sample`.
  const double sample = static_cast<double>(end_sample);
  const double host = host_s - latency_s_;
  if (!anchored_) {
    anchored_ = true;
    anchor_sample_ = sample;
    anchor_host_ = host;
  }
  points_.push_back({sample - anchor_sample_, host - anchor_host_});
  ++observed_;
  const double oldest_allowed = points_.back().sample - window_s_ * nominal_rate_;
  while (points_.size() > 2 && points_.front().sample < oldest_allowed) points_.pop_front();
  if (points_.size() < 16 || observed_ % kRefitEvery == 0) refit();
}

void ClockModel::refit() {
  const size_t n = points_.size();
  if (n == 1) {
    slope_ = 1.0 / nominal_rate_;
    intercept_ = points_.front().host - slope_ * points_.front().sample;
    jitter_s_ = 0.0;
    return;
  }
  // Least squares about the means (well conditioned however long the session runs).
  double mean_s = 0.0, mean_h = 0.0;
  for (const Point& p : points_) {
    mean_s += p.sample;
    mean_h += p.host;
  }
  mean_s /= static_cast<double>(n);
  mean_h /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (const Point& p : points_) {
    sxx += (p.sample - mean_s) * (p.sample - mean_s);
    sxy += (p.sample - mean_s) * (p.host - mean_h);
  }
  if (sxx <= 0.0) return;
  slope_ = sxy / sxx;
  // A fit over a short span can be wild: keep it within 1 % of the nominal rate.
  slope_ = std::clamp(slope_, 0.99 / nominal_rate_, 1.01 / nominal_rate_);
  intercept_ = mean_h - slope_ * mean_s;
  std::vector<double> residuals;
  residuals.reserve(n);
  double sum_squares = 0.0;
  for (const Point& p : points_) {
    const double r = p.host - (intercept_ + slope_ * p.sample);
    residuals.push_back(r);
    sum_squares += r * r;
  }
  jitter_s_ = std::sqrt(sum_squares / static_cast<double>(n));
  const size_t k = static_cast<size_t>(kEnvelopeQuantile * static_cast<double>(n - 1));
  std::nth_element(residuals.begin(), residuals.begin() + static_cast<std::ptrdiff_t>(k),
                   residuals.end());
  intercept_ += residuals[k];
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
