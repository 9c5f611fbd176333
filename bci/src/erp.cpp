#include "arbci/bci/erp.h"

#include "arbci/bci/electrode_positions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace arbci::bci {

std::vector<double> ErpCurves::row(const Eigen::MatrixXd& m, int channel) {
  const auto r = m.row(channel);
  return std::vector<double>(r.begin(), r.end());
}

ErpAccumulator::ErpAccumulator(int channels, int samples, int baseline_samples)
    : channels_(channels), samples_(samples), baseline_samples_(baseline_samples) {
  if (baseline_samples < 1 || baseline_samples >= samples)
    throw std::invalid_argument("an ERP epoch needs a baseline of at least one sample before it");
  for (int k = 0; k < 2; ++k) {
    sum_[k] = Eigen::MatrixXd::Zero(channels, samples);
    sum_sq_[k] = Eigen::MatrixXd::Zero(channels, samples);
  }
}

void ErpAccumulator::add(const std::vector<float>& epoch, bool target) {
  const int k = target ? 0 : 1;
  ++n_[k];
  for (int c = 0; c < channels_; ++c) {
    const float* x = epoch.data() + static_cast<size_t>(c) * samples_;
    double baseline = 0.0;
    for (int s = 0; s < baseline_samples_; ++s) baseline += x[s];
    baseline /= baseline_samples_;
    for (int s = 0; s < samples_; ++s) {
      const double v = x[s] - baseline;
      sum_[k](c, s) += v;
      sum_sq_[k](c, s) += v * v;
    }
  }
}

std::string ErpCurves::filterText() const {
  const auto hz = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  if (!filtered()) return "unfiltered";
  std::string band;
  const auto ordinal = [](int n) {
    const int tens = n % 100, ones = n % 10;
    const char* suffix = tens >= 11 && tens <= 13 ? "th"
                         : ones == 1              ? "st"
                         : ones == 2              ? "nd"
                         : ones == 3              ? "rd"
                                                  : "th";
    return std::to_string(n) + suffix;
  };
  const std::string butterworth =
      (filter_order > 0 ? ordinal(filter_order) + "-order " : std::string()) + "Butterworth ";
  if (highpass_hz > 0.0 && lowpass_hz > 0.0)
    band = butterworth + hz(highpass_hz) + "-" + hz(lowpass_hz) + " Hz band-pass";
  else if (highpass_hz > 0.0)
    band = butterworth + hz(highpass_hz) + " Hz high-pass";
  else if (lowpass_hz > 0.0)
    band = butterworth + hz(lowpass_hz) + " Hz low-pass";
  if (notch_hz > 0.0)
    band += (band.empty() ? "" : ", ") + hz(notch_hz) + " Hz notch" +
            (notch_q > 0.0 ? " (Q " + hz(notch_q) + ")" : std::string());
  return band + (zero_phase ? ", zero-phase" : ", causal (as online)");
}

std::string ErpCurves::referenceText() const {
  return common_average ? "common average" : "as recorded";
}

int ErpCurves::peakSample() const {
  if (samples() == 0) return 0;
  Eigen::Index peak = 0;
  difference().colwise().squaredNorm().maxCoeff(&peak);
  return static_cast<int>(peak);
}

double ErpCurves::scaleUv() const {
  return std::ceil(std::max({1.0, (target_mean.cwiseAbs() + 1.96 * target_se).maxCoeff(),
                             (other_mean.cwiseAbs() + 1.96 * other_se).maxCoeff(),
                             difference().cwiseAbs().maxCoeff()}));
}

double ScalpMap::at(double x, double y) const {
  double weighted = 0.0, weights = 0.0;
  for (const Electrode& e : electrodes) {
    const double d2 = (x - e.x) * (x - e.x) + (y - e.y) * (y - e.y);
    if (d2 < 1e-12) return e.uv;
    weighted += e.uv / d2;
    weights += 1.0 / d2;
  }
  return weights > 0.0 ? weighted / weights : 0.0;
}

int scalpSample(const ErpCurves& erp, const ScalpTime& when) {
  const int n = erp.samples();
  if (n == 0) return 0;
  auto sampleAt = [&](double t) {
    return std::clamp(static_cast<int>(std::lround((t - erp.start_s) * erp.rate_hz)), 0, n - 1);
  };
  if (when.at_s) return sampleAt(*when.at_s);
  int from = sampleAt(when.from_s), to = sampleAt(when.to_s);
  if (erp.timeS(to) < when.from_s || erp.timeS(from) > when.to_s) {
    from = 0;  // the window lies outside the epoch: its whole length
    to = n - 1;
  }
  // A peak: the largest local maximum inside the window (a difference still falling from an
  // earlier peak is largest at the window's first sample, which is no peak); failing one, the
  // window's largest value.
  const Eigen::VectorXd power = erp.difference().colwise().squaredNorm().transpose();
  int best = -1;
  for (int s = from; s <= to; ++s) {
    const bool local =
        (s == 0 || power(s) >= power(s - 1)) && (s == n - 1 || power(s) >= power(s + 1));
    if (local && (best < 0 || power(s) > power(best))) best = s;
  }
  if (best >= 0) return best;
  Eigen::Index peak = 0;
  power.segment(from, to - from + 1).maxCoeff(&peak);
  return from + static_cast<int>(peak);
}

std::optional<ScalpMap> scalpMapAt(const ErpCurves& erp, const ScalpTime& when) {
  if (erp.samples() == 0) return std::nullopt;
  const int peak = scalpSample(erp, when);
  const Eigen::MatrixXd difference = erp.difference();
  ScalpMap map;
  map.time_s = erp.timeS(peak);
  map.limit_uv = 1e-6;
  for (size_t c = 0; c < erp.channels.size(); ++c) {
    if (const auto at = electrodePosition(erp.channels[c])) {
      const double uv = difference(static_cast<Eigen::Index>(c), peak);
      map.electrodes.push_back({erp.channels[c], at->first, at->second, uv});
      map.limit_uv = std::max(map.limit_uv, std::abs(uv));
    }
  }
  if (map.electrodes.size() < 3) return std::nullopt;
  return map;
}

ErpCurves ErpAccumulator::curves() const {
  ErpCurves out;
  out.targets = n_[0];
  out.others = n_[1];
  Eigen::MatrixXd* means[2] = {&out.target_mean, &out.other_mean};
  Eigen::MatrixXd* errors[2] = {&out.target_se, &out.other_se};
  for (int k = 0; k < 2; ++k) {
    const double n = n_[k];
    *means[k] = n > 0 ? Eigen::MatrixXd(sum_[k] / n) : Eigen::MatrixXd::Zero(channels_, samples_);
    *errors[k] = Eigen::MatrixXd::Zero(channels_, samples_);
    if (n < 2) continue;
    // Sample variance from the sums; clamped at 0 against rounding.
    const Eigen::MatrixXd variance =
        ((sum_sq_[k] - sum_[k].cwiseProduct(sum_[k]) / n) / (n - 1.0)).cwiseMax(0.0);
    *errors[k] = (variance / n).cwiseSqrt();
  }
  // Point-biserial r over both classes: (m1 - m0) sqrt(n1 n0) / (n s), s the pooled SD about
  // the grand mean (population form).
  out.signed_r2 = Eigen::MatrixXd::Zero(channels_, samples_);
  const double n1 = n_[0], n0 = n_[1], n = n1 + n0;
  if (n1 > 0 && n0 > 0) {
    const Eigen::MatrixXd mean = (sum_[0] + sum_[1]) / n;
    const Eigen::MatrixXd variance =
        ((sum_sq_[0] + sum_sq_[1]) / n - mean.cwiseProduct(mean)).cwiseMax(1e-30);
    const Eigen::MatrixXd r = (out.target_mean - out.other_mean) * std::sqrt(n1 * n0) / n;
    const Eigen::MatrixXd r_scaled = r.cwiseQuotient(variance.cwiseSqrt());
    out.signed_r2 = r_scaled.cwiseProduct(r_scaled.cwiseAbs());
  }
  return out;
}

}  // namespace arbci::bci
