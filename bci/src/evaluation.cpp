#include "arbci/bci/evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace arbci::bci {

double areaUnderCurve(const std::vector<double>& scores, const std::vector<bool>& target) {
  std::vector<size_t> order(scores.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return scores[a] < scores[b]; });
  // Rank sum of the targets with average ranks for ties.
  double rank_sum = 0.0;
  size_t n_target = 0;
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j < order.size() && scores[order[j]] == scores[order[i]]) ++j;
    const double rank = 0.5 * static_cast<double>(i + j + 1);
    for (size_t k = i; k < j; ++k) {
      if (target[order[k]]) {
        rank_sum += rank;
        ++n_target;
      }
    }
    i = j;
  }
  const size_t n_other = scores.size() - n_target;
  if (n_target == 0 || n_other == 0) return 0.5;
  return (rank_sum - 0.5 * static_cast<double>(n_target) * static_cast<double>(n_target + 1)) /
         (static_cast<double>(n_target) * static_cast<double>(n_other));
}

double wolpawBits(int choices, double p) {
  if (choices < 2) return 0.0;
  const double n = choices;
  if (p <= 1.0 / n) return 0.0;
  double bits = std::log2(n);
  if (p > 0.0) bits += p * std::log2(p);
  if (p < 1.0) bits += (1.0 - p) * std::log2((1.0 - p) / (n - 1.0));
  return bits;
}

std::string EvaluationReport::selected(int sequences) const {
  std::string out;
  const bool speller = !layout.symbols.empty();
  for (const SelectionResult& s : selections) {
    const Decision& d =
        s.by_sequences[static_cast<size_t>(std::clamp(sequences, 1, max_sequences) - 1)];
    if (!speller && !out.empty()) out += ", ";
    out += layout.describe(d.codes);
  }
  return out;
}

std::string EvaluationReport::selectedDynamic() const {
  std::string out;
  for (const SelectionResult& s : selections) {
    if (layout.symbols.empty() && !out.empty()) out += ", ";
    out += layout.describe(s.dynamic.codes);
  }
  return out;
}

EvaluationReport evaluateScores(const P300Dataset& data, const std::vector<double>& scores,
                                const ScoreModel& model, const StoppingRule& dynamic) {
  EvaluationReport report;
  report.layout = data.layout;
  report.dynamic_rule = dynamic;
  std::vector<double> tested_scores;
  std::vector<bool> tested_labels;
  for (const SelectionEpochs& s : data.selections) {
    if (s.target_codes.empty()) continue;
    for (int row : s.epochs) {
      tested_scores.push_back(scores[static_cast<size_t>(row)]);
      tested_labels.push_back(data.target[static_cast<size_t>(row)]);
    }
  }
  report.auc = areaUnderCurve(tested_scores, tested_labels);
  // Sequences every selection has.
  report.max_sequences = std::numeric_limits<int>::max();
  for (const SelectionEpochs& s : data.selections) {
    int complete = 0;
    if (!s.epochs.empty()) complete = data.sequence[static_cast<size_t>(s.epochs.back())] + 1;
    if (static_cast<int>(s.epochs.size()) < complete * data.layout.codes())
      --complete;  // last one cut short
    report.max_sequences = std::min(report.max_sequences, complete);
  }
  if (data.selections.empty() || report.max_sequences < 1)
    throw std::invalid_argument("no selection has a whole sequence");
  const int n_max = report.max_sequences;
  report.accuracy.assign(static_cast<size_t>(n_max), 0.0);

  double dynamic_correct = 0.0, dynamic_flashes = 0.0;
  for (const SelectionEpochs& s : data.selections) {
    SelectionResult result;
    result.truth = s.target_codes;
    SelectionAccumulator fixed(data.layout, model), adaptive(data.layout, model);
    bool stopped = false;
    int sequence = 0;
    for (int row : s.epochs) {
      const size_t i = static_cast<size_t>(row);
      if (data.sequence[i] >= n_max) break;
      if (data.sequence[i] != sequence) {  // a sequence just ended
        result.by_sequences.push_back(fixed.decide());
        if (!stopped && adaptive.shouldStop(dynamic)) stopped = true;
        sequence = data.sequence[i];
      }
      fixed.add(data.code[i], scores[i]);
      if (!stopped) adaptive.add(data.code[i], scores[i]);
    }
    result.by_sequences.push_back(fixed.decide());
    result.dynamic = adaptive.decide();
    result.dynamic_sequences = adaptive.completeSequences();
    result.dynamic_flashes = adaptive.flashes();
    dynamic_flashes += result.dynamic_flashes;
    if (!result.truth.empty()) {
      ++report.selections_with_truth;
      for (int n = 0; n < n_max; ++n)
        report.accuracy[static_cast<size_t>(n)] +=
            result.by_sequences[static_cast<size_t>(n)].codes == result.truth;
      dynamic_correct += result.dynamic.codes == result.truth;
    }
    report.selections.push_back(std::move(result));
  }
  const double known = std::max(1, report.selections_with_truth);
  for (int n = 0; n < n_max; ++n) {
    report.accuracy[static_cast<size_t>(n)] /= known;
    const double seconds = (n + 1) * data.layout.codes() * data.layout.soa_s;
    report.seconds_per_selection.push_back(seconds);
    report.bits_per_minute.push_back(
        wolpawBits(data.layout.choices(), report.accuracy[static_cast<size_t>(n)]) * 60.0 /
        seconds);
  }
  report.dynamic_accuracy = dynamic_correct / known;
  report.dynamic_mean_flashes = dynamic_flashes / static_cast<double>(data.selections.size());
  report.dynamic_seconds = report.dynamic_mean_flashes * data.layout.soa_s;
  report.dynamic_bits_per_minute =
      wolpawBits(data.layout.choices(), report.dynamic_accuracy) * 60.0 / report.dynamic_seconds;
  return report;
}

CrossValidation crossValidate(const P300Dataset& data, const TrainingSettings& settings,
                              const Progress& progress) {
  std::vector<int> labelled;
  for (size_t s = 0; s < data.selections.size(); ++s) {
    if (!data.selections[s].target_codes.empty()) labelled.push_back(static_cast<int>(s));
  }
  if (labelled.size() < 2) {
    throw std::invalid_argument(
        "cross-validation needs at least 2 selections with known targets, the data have " +
        std::to_string(labelled.size()));
  }
  CrossValidation cv;
  cv.folds = std::clamp(settings.folds, 2, static_cast<int>(labelled.size()));
  cv.scores.assign(static_cast<size_t>(data.epochs()), 0.0);
  std::vector<int> fold_of(data.selections.size(), -1);
  for (size_t k = 0; k < labelled.size(); ++k)
    fold_of[static_cast<size_t>(labelled[k])] = static_cast<int>(k * cv.folds / labelled.size());
  for (int fold = 0; fold < cv.folds; ++fold) {
    std::vector<int> train_rows, test_rows;
    for (int row = 0; row < data.epochs(); ++row) {
      const int f = fold_of[static_cast<size_t>(data.selection[static_cast<size_t>(row)])];
      if (f < 0) continue;
      (f == fold ? test_rows : train_rows).push_back(row);
    }
    Eigen::MatrixXd x(static_cast<Eigen::Index>(train_rows.size()), data.features.cols());
    std::vector<bool> y;
    for (size_t i = 0; i < train_rows.size(); ++i) {
      x.row(static_cast<Eigen::Index>(i)) = data.features.row(train_rows[i]);
      y.push_back(data.target[static_cast<size_t>(train_rows[i])]);
    }
    auto classifier = makeClassifier(settings.method, settings.swlda, settings.xdawn);
    const Progress inner = progress ? Progress([&](double f, const std::string& stage) {
      progress((fold + f) / (cv.folds + 1.0),
               "fold " + std::to_string(fold + 1) + "/" + std::to_string(cv.folds) + ": " + stage);
    })
                                    : Progress();
    classifier->train(x, y, data.shape, inner);
    for (int row : test_rows)
      cv.scores[static_cast<size_t>(row)] = classifier->score(data.features.row(row).transpose());
  }
  // Only labelled selections take part in the report.
  P300Dataset tested = data;
  tested.selections.clear();
  for (int s : labelled) tested.selections.push_back(data.selections[static_cast<size_t>(s)]);
  std::vector<double> scored;
  std::vector<bool> labels;
  for (const SelectionEpochs& s : tested.selections) {
    for (int row : s.epochs) {
      scored.push_back(cv.scores[static_cast<size_t>(row)]);
      labels.push_back(data.target[static_cast<size_t>(row)]);
    }
  }
  cv.score_model = ScoreModel::fit(scored, labels);
  cv.report = evaluateScores(tested, cv.scores, cv.score_model, settings.dynamic);
  return cv;
}

}  // namespace arbci::bci
