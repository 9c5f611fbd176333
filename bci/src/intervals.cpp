#include "arbci/bci/intervals.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

namespace arbci::bci {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

Interval aucInterval(double auc, int targets, int others) {
  if (targets < 1 || others < 1) return {0.0, 1.0};
  const double a = auc, q1 = a / (2.0 - a), q2 = 2.0 * a * a / (1.0 + a);
  const double variance =
      (a * (1.0 - a) + (targets - 1.0) * (q1 - a * a) + (others - 1.0) * (q2 - a * a)) /
      (static_cast<double>(targets) * others);
  const double half = 1.96 * std::sqrt(std::max(variance, 0.0));
  return {std::max(0.0, a - half), std::min(1.0, a + half)};
}

Interval wilsonInterval(int successes, int trials) {
  if (trials < 1) return {0.0, 1.0};
  const double z = 1.96, n = trials, p = successes / n;
  const double centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
  const double half = z * std::sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / (1.0 + z * z / n);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

double chanceLevel95(int choices, int trials) {
  if (choices < 2 || trials < 1) return 1.0;
  const double p = 1.0 / choices;
  // P(X >= k) for X ~ Binomial(trials, p), from k = trials down.
  double tail = 0.0;
  for (int k = trials; k >= 0; --k) {
    const double log_term = std::lgamma(trials + 1.0) - std::lgamma(k + 1.0) -
                            std::lgamma(trials - k + 1.0) + k * std::log(p) +
                            (trials - k) * std::log1p(-p);
    tail += std::exp(log_term);
    if (tail >= 0.05) return std::min(1.0, (k + 1.0) / trials);
  }
  return 0.0;
}

namespace {

// The smallest and largest wrong counts inside the central 95 % of the Poisson-binomial
// distribution of independent wrong-probabilities `p_wrong`.
std::pair<int, int> wrongInterval(const std::vector<double>& p_wrong) {
  std::vector<double> p(p_wrong.size() + 1, 0.0);
  p[0] = 1.0;
  for (size_t i = 0; i < p_wrong.size(); ++i) {
    const double w = p_wrong[i];
    for (size_t k = i + 1; k > 0; --k) p[k] = p[k] * (1.0 - w) + p[k - 1] * w;
    p[0] *= 1.0 - w;
  }
  double below = 0.0;
  int low = -1, high = 0;
  for (size_t k = 0; k < p.size(); ++k) {
    below += p[k];
    if (low < 0 && below > 0.025) low = static_cast<int>(k);
    if (below < 0.975) high = static_cast<int>(k) + 1;
  }
  return {std::max(low, 0), std::min(high, static_cast<int>(p_wrong.size()))};
}

}  // namespace

std::vector<ReliabilityBand> reliabilityBands(const std::vector<ClaimedDecision>& decisions) {
  static constexpr double kEdges[] = {0.0, 0.9, 0.99, 0.999, 1.0};
  std::vector<ReliabilityBand> bands;
  for (int b = 0; b < 4; ++b) {
    ReliabilityBand band{kEdges[b], kEdges[b + 1]};
    std::vector<double> p_wrong;
    for (const ClaimedDecision& d : decisions) {
      const bool last = b == 3;
      if (d.certainty < band.low || (last ? d.certainty > band.high : d.certainty >= band.high))
        continue;
      ++band.decisions;
      band.wrong += !d.right;
      p_wrong.push_back(std::clamp(1.0 - d.certainty, 0.0, 1.0));
      band.expected_wrong += p_wrong.back();
    }
    if (band.decisions == 0) continue;
    std::tie(band.wrong_low, band.wrong_high) = wrongInterval(p_wrong);
    bands.push_back(band);
  }
  return bands;
}

}  // namespace arbci::bci
