#include "arbci/bci/held_out_separation.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace arbci::bci {
namespace {

struct CodeSums {
  double n = 0.0, sum = 0.0, squares = 0.0;
};

// The codes among which exactly one is attended: all stimuli, or the rows and the columns apart.
std::vector<std::vector<int>> groupsOf(const ParadigmLayout& layout) {
  std::vector<std::vector<int>> groups;
  if (layout.kind == ParadigmLayout::Kind::RowColumn) {
    groups.resize(2);
    for (int c = 1; c <= layout.rows; ++c) groups[0].push_back(c);
    for (int c = layout.rows + 1; c <= layout.rows + layout.columns; ++c) groups[1].push_back(c);
  } else {
    groups.resize(1);
    for (int c = 1; c <= layout.stimuli; ++c) groups[0].push_back(c);
  }
  return groups;
}

struct Means {
  double target = 0.0, other = 0.0, sd = 1.0;
  double separation() const { return (target - other) / sd; }
};

// The class means and pooled standard deviation with each code weighted by its probability of
// being the attended one.
Means weightedMeans(const std::vector<std::vector<CodeSums>>& groups,
                    const std::vector<std::vector<double>>& weight) {
  double target_sum = 0.0, target_n = 0.0, other_sum = 0.0, other_n = 0.0;
  for (size_t g = 0; g < groups.size(); ++g) {
    for (size_t c = 0; c < groups[g].size(); ++c) {
      const CodeSums& s = groups[g][c];
      const double w = weight[g][c];
      target_sum += w * s.sum;
      target_n += w * s.n;
      other_sum += (1.0 - w) * s.sum;
      other_n += (1.0 - w) * s.n;
    }
  }
  Means m;
  m.target = target_n > 0.0 ? target_sum / target_n : 0.0;
  m.other = other_n > 0.0 ? other_sum / other_n : 0.0;
  double squares = 0.0;
  for (size_t g = 0; g < groups.size(); ++g) {
    for (size_t c = 0; c < groups[g].size(); ++c) {
      const CodeSums& s = groups[g][c];
      const double w = weight[g][c];
      auto around = [&](double mean) { return s.squares - 2.0 * mean * s.sum + s.n * mean * mean; };
      squares += w * around(m.target) + (1.0 - w) * around(m.other);
    }
  }
  const double n = target_n + other_n;
  m.sd = std::sqrt(std::max(squares / std::max(n, 1.0), 1e-12));
  return m;
}

}  // namespace

double standardised(const ScoreModel& model, double score) {
  return (score - 0.5 * (model.target_mean + model.other_mean)) / model.sd;
}

std::optional<double> heldOutSeparation(const std::vector<HeldOutSelection>& selections,
                                        const ParadigmLayout& layout) {
  const std::vector<std::vector<int>> codes = groupsOf(layout);
  // Per selection and group: each candidate code's sums.
  std::vector<std::vector<CodeSums>> groups;
  for (const HeldOutSelection& selection : selections) {
    std::map<int, CodeSums> sums;
    for (size_t i = 0; i < selection.code.size() && i < selection.z.size(); ++i) {
      CodeSums& s = sums[selection.code[i]];
      s.n += 1.0;
      s.sum += selection.z[i];
      s.squares += selection.z[i] * selection.z[i];
    }
    for (const std::vector<int>& group : codes) {
      std::vector<CodeSums> candidates;
      int flashed = 0;
      for (int code : group) {
        const auto found = sums.find(code);
        candidates.push_back(found != sums.end() ? found->second : CodeSums{});
        flashed += found != sums.end();
      }
      if (flashed >= 2) groups.push_back(std::move(candidates));
    }
  }
  if (groups.empty()) return std::nullopt;
  // Start: each group's highest-scoring code taken as its target (the hard choice, which
  // overstates the separation); EM then weighs every code by its posterior.
  std::vector<std::vector<double>> weight(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    weight[g].assign(groups[g].size(), 0.0);
    size_t best = 0;
    double top = -1e300;
    for (size_t c = 0; c < groups[g].size(); ++c) {
      const CodeSums& s = groups[g][c];
      if (s.n > 0.0 && s.sum / s.n > top) {
        top = s.sum / s.n;
        best = c;
      }
    }
    weight[g][best] = 1.0;
  }
  Means m = weightedMeans(groups, weight);
  for (int iteration = 0; iteration < 500; ++iteration) {
    const double d = m.target - m.other, mid = 0.5 * (m.target + m.other);
    for (size_t g = 0; g < groups.size(); ++g) {
      std::vector<double> log_odds(groups[g].size());
      double top = -1e300;
      for (size_t c = 0; c < groups[g].size(); ++c) {
        const CodeSums& s = groups[g][c];
        log_odds[c] = d * (s.sum - s.n * mid) / (m.sd * m.sd);
        top = std::max(top, log_odds[c]);
      }
      double total = 0.0;
      for (size_t c = 0; c < groups[g].size(); ++c)
        total += weight[g][c] = std::exp(log_odds[c] - top);
      for (double& w : weight[g]) w /= total;
    }
    const Means next = weightedMeans(groups, weight);
    const bool settled = std::abs(next.separation() - m.separation()) < 1e-9;
    m = next;
    if (settled) break;
  }
  return m.separation();
}

ScoreModel boundSeparation(const ScoreModel& fitted, double separation) {
  if (separation >= fitted.separation()) return fitted;
  ScoreModel bounded = fitted;
  const double mid = 0.5 * (fitted.target_mean + fitted.other_mean);
  const double half = 0.5 * std::max(separation, 0.0) * fitted.sd;
  bounded.target_mean = mid + half;
  bounded.other_mean = mid - half;
  return bounded;
}

SeparationBound boundByHeldOut(ScoreModel& model, const std::vector<HeldOutSelection>& selections,
                               const ParadigmLayout& layout) {
  SeparationBound out{model.separation(), heldOutSeparation(selections, layout)};
  if (out.held_out) model = boundSeparation(model, *out.held_out);
  return out;
}

}  // namespace arbci::bci
