#include "arbci/bci/decision.h"

#include "arbci/bci/intervals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

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

int SelectionAccumulator::completeSequences() const {
  int least = std::numeric_limits<int>::max();
  for (const auto& [code, count] : counts_) least = std::min(least, count);
  return counts_.empty() ? 0 : least;
}

std::map<int, double> SelectionAccumulator::posterior(int first_code, int count) const {
  double top = -std::numeric_limits<double>::infinity();
  for (int c = first_code; c < first_code + count; ++c) top = std::max(top, evidence_.at(c));
  std::map<int, double> p;
  double total = 0.0;
  for (int c = first_code; c < first_code + count; ++c)
    total += p[c] = std::exp(evidence_.at(c) - top);
  for (auto& [code, value] : p) value /= total;
  return p;
}

Decision SelectionAccumulator::decide() const {
  Decision decision;
  auto best = [](const std::map<int, double>& p) {
    return *std::max_element(p.begin(), p.end(),
                             [](const auto& a, const auto& b) { return a.second < b.second; });
  };
  if (layout_.kind == ParadigmLayout::Kind::RowColumn) {
    const auto row = best(posterior(1, layout_.rows));
    const auto column = best(posterior(layout_.rows + 1, layout_.columns));
    decision.codes = {row.first, column.first};
    decision.choice = (row.first - 1) * layout_.columns + (column.first - layout_.rows - 1);
    decision.certainty = row.second * column.second;
  } else {
    const auto object = best(posterior(1, layout_.stimuli));
    decision.codes = {object.first};
    decision.choice = object.first - 1;
    decision.certainty = object.second;
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
