#include "arbci/bci/decision.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

#include "arbci/bci/intervals.h"

namespace arbci::bci {

ScoreModel ScoreModel::fit(const std::vector<double>& scores, const std::vector<bool>& target) {
  double sum[2] = {0.0, 0.0}, sum2[2] = {0.0, 0.0};
  int n[2] = {0, 0};
  for (size_t i = 0; i < scores.size(); ++i) {
    const int k = target[i] ? 1 : 0;
    sum[k] += scores[i];
    sum2[k] += scores[i] * scores[i];
    ++n[k];
  }
  if (n[0] < 2 || n[1] < 2)
    throw std::invalid_argument("score model: needs target and non-target scores");
  ScoreModel model;
  model.target_mean = sum[1] / n[1];
  model.other_mean = sum[0] / n[0];
  const double within = (sum2[1] - n[1] * model.target_mean * model.target_mean) +
                        (sum2[0] - n[0] * model.other_mean * model.other_mean);
  model.sd = std::sqrt(std::max(within / (n[0] + n[1] - 2), 1e-12));
  model.median = bci::median(scores);
  return model;
}

double fitWithinSelectionCorrelation(const ScoreModel& model, const std::vector<double>& scores,
                                     const std::vector<bool>& target,
                                     const std::vector<int>& selection,
                                     const std::vector<int>& code) {
  // Each flash's residual from its class mean, by selection and code.
  std::map<int, std::map<int, std::vector<double>>> residuals;
  for (size_t i = 0; i < scores.size(); ++i)
    residuals[selection[i]][code[i]].push_back(scores[i] -
                                               (target[i] ? model.target_mean : model.other_mean));
  // Within a selection (what it shares removed), residuals of variance t^2 correlate by rho
  // within a code. Over a selection of N flashes in K codes of n_c each:
  //   E[sum_i (r_i - mean r)^2]       = t^2 (N - 1 + rho (1 - sum n_c^2 / N))
  //   E[sum_c (m_c - mean of m_c)^2]  = t^2 (1 - 1/K) (sum 1/n_c + rho (K - sum 1/n_c))
  // (m_c a code's mean residual). The ratio of the two sums is free of t^2: solved for rho.
  double flashes_scatter = 0.0, codes_scatter = 0.0;
  double a0 = 0.0, a1 = 0.0, b0 = 0.0, b1 = 0.0;
  for (const auto& [number, codes] : residuals) {
    if (codes.size() < 2) continue;
    const double k = static_cast<double>(codes.size());
    double n_all = 0.0, sum_all = 0.0, squares_counts = 0.0, inverse_counts = 0.0,
           mean_of_means = 0.0;
    for (const auto& [c, r] : codes) {
      const double n = static_cast<double>(r.size());
      double sum = 0.0;
      for (double v : r) sum += v;
      n_all += n;
      sum_all += sum;
      squares_counts += n * n;
      inverse_counts += 1.0 / n;
      mean_of_means += sum / n / k;
    }
    const double mean_all = sum_all / n_all;
    for (const auto& [c, r] : codes) {
      double sum = 0.0;
      for (double v : r) {
        flashes_scatter += (v - mean_all) * (v - mean_all);
        sum += v;
      }
      const double d = sum / static_cast<double>(r.size()) - mean_of_means;
      codes_scatter += d * d;
    }
    a0 += n_all - 1.0;
    a1 += 1.0 - squares_counts / n_all;
    b0 += (1.0 - 1.0 / k) * inverse_counts;
    b1 += (1.0 - 1.0 / k) * (k - inverse_counts);
  }
  if (flashes_scatter <= 0.0 || b1 <= 0.0) return 0.0;
  const double ratio = codes_scatter / flashes_scatter;
  const double denominator = ratio * a1 - b1;
  if (std::abs(denominator) < 1e-12) return 0.0;
  return std::clamp((b0 - ratio * a0) / denominator, 0.0, 0.5);
}

SelectionAccumulator::SelectionAccumulator(const ParadigmLayout& layout, const ScoreModel& model)
    : layout_(layout), model_(model) {
  for (int code = 1; code <= layout.codes(); ++code) {
    evidence_[code] = 0.0;
    counts_[code] = 0;
  }
}

void SelectionAccumulator::add(int code, double score) {
  auto found = evidence_.find(code);
  if (found == evidence_.end()) return;  // a code the paradigm does not use
  const double a = score - model_.target_mean, b = score - model_.other_mean;
  found->second += (b * b - a * a) / (2.0 * model_.sd * model_.sd);
  ++counts_[code];
  ++flashes_;
}

double SelectionAccumulator::discounted(int code) const {
  return evidence_.at(code) / model_.overdispersion(counts_.at(code));
}

int SelectionAccumulator::completeSequences() const {
  int least = std::numeric_limits<int>::max();
  for (const auto& [code, count] : counts_) least = std::min(least, count);
  return counts_.empty() ? 0 : least;
}

std::map<int, double> SelectionAccumulator::posterior(int first_code, int count) const {
  double top = -std::numeric_limits<double>::infinity();
  for (int c = first_code; c < first_code + count; ++c) top = std::max(top, discounted(c));
  std::map<int, double> p;
  double total = 0.0;
  for (int c = first_code; c < first_code + count; ++c)
    total += p[c] = std::exp(discounted(c) - top);
  for (auto& [code, value] : p) value /= total;
  return p;
}

double errorPosterior(const ScoreModel& errp, double score, double prior_error) {
  const double prior = std::clamp(prior_error, 0.01, 0.99);
  const double a = score - errp.target_mean, b = score - errp.other_mean;
  // log p(score | error) - log p(score | correct), equal variances.
  const double log_ratio = (b * b - a * a) / (2.0 * errp.sd * errp.sd);
  const double log_odds = std::clamp(log_ratio + std::log(prior / (1.0 - prior)), -700.0, 700.0);
  return 1.0 / (1.0 + std::exp(-log_odds));
}

Decision SelectionAccumulator::decide() const {
  Decision decision;
  decision.evidence = evidence_;
  decision.flashes = counts_;
  using Entry = std::pair<int, double>;
  auto ranked = [](const std::map<int, double>& p) {
    std::vector<Entry> order(p.begin(), p.end());
    std::stable_sort(order.begin(), order.end(),
                     [](const Entry& a, const Entry& b) { return a.second > b.second; });
    return order;
  };
  if (layout_.kind == ParadigmLayout::Kind::RowColumn) {
    const auto rows = ranked(posterior(1, layout_.rows));
    const auto columns = ranked(posterior(layout_.rows + 1, layout_.columns));
    auto cell = [&](const Entry& row, const Entry& column) {
      return (row.first - 1) * layout_.columns + (column.first - layout_.rows - 1);
    };
    decision.codes = {rows[0].first, columns[0].first};
    decision.choice = cell(rows[0], columns[0]);
    decision.certainty = rows[0].second * columns[0].second;
    const double other_row = rows.size() > 1 ? rows[1].second * columns[0].second : -1.0;
    const double other_column = columns.size() > 1 ? rows[0].second * columns[1].second : -1.0;
    if (other_row >= 0.0 || other_column >= 0.0) {
      const Entry& row = other_row >= other_column ? rows[1] : rows[0];
      const Entry& column = other_row >= other_column ? columns[0] : columns[1];
      decision.runner_up_codes = {row.first, column.first};
      decision.runner_up_choice = cell(row, column);
      decision.runner_up_certainty = std::max(other_row, other_column);
    }
  } else {
    const auto objects = ranked(posterior(1, layout_.stimuli));
    decision.codes = {objects[0].first};
    decision.choice = objects[0].first - 1;
    decision.certainty = objects[0].second;
    if (objects.size() > 1) {
      decision.runner_up_codes = {objects[1].first};
      decision.runner_up_choice = objects[1].first - 1;
      decision.runner_up_certainty = objects[1].second;
    }
  }
  return decision;
}

bool SelectionAccumulator::shouldStop(const StoppingRule& rule) const {
  const int done = completeSequences();
  if (done >= rule.max_sequences) return true;
  if (rule.certainty <= 0.0 || done < rule.min_sequences) return false;
  return decide().certainty >= rule.certainty;
}

}  // namespace arbci::bci
