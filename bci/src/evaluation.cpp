#include "arbci/bci/evaluation.h"

#include "xdawn_filters.h"

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
    const int own = static_cast<int>(s.by_sequences.size());
    const Decision& d = s.by_sequences[static_cast<size_t>(std::clamp(sequences, 1, own) - 1)];
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
  report.target_flashes =
      static_cast<int>(std::count(tested_labels.begin(), tested_labels.end(), true));
  report.other_flashes = static_cast<int>(tested_labels.size()) - report.target_flashes;
  report.auc_interval = aucInterval(report.auc, report.target_flashes, report.other_flashes);
  if (data.codes_are_classes) {
    report.selection_metrics = false;
    return report;
  }
  // Each selection's whole sequences.
  auto wholeSequences = [&](const SelectionEpochs& s) {
    if (s.epochs.empty()) return 0;
    const int seen = data.sequence[static_cast<size_t>(s.epochs.back())] + 1;
    return static_cast<int>(s.epochs.size()) < seen * data.layout.codes() ? seen - 1 : seen;
  };
  // The run's number of sequences: what at least half of its selections have, so that neither
  // a selection cut short nor one longer than the rest (a dynamic stop that ran on) sets it.
  std::vector<int> whole;
  for (const SelectionEpochs& s : data.selections) {
    if (const int n = wholeSequences(s); n >= 1) whole.push_back(n);
  }
  if (whole.empty()) throw std::invalid_argument("no selection has a whole sequence");
  std::sort(whole.begin(), whole.end());
  report.max_sequences = whole[whole.size() / 2];
  const int n_max = report.max_sequences;
  std::vector<int> correct(static_cast<size_t>(n_max), 0);
  report.selections_by_sequences.assign(static_cast<size_t>(n_max), 0);

  int dynamic_correct = 0;
  double dynamic_flashes = 0.0;
  for (const SelectionEpochs& s : data.selections) {
    const int own = std::min(wholeSequences(s), n_max);
    if (own < 1) {
      ++report.fragments;
      continue;
    }
    SelectionResult result;
    result.truth = s.target_codes;
    SelectionAccumulator fixed(data.layout, model), adaptive(data.layout, model);
    bool stopped = false;
    int sequence = 0;
    for (int row : s.epochs) {
      const size_t i = static_cast<size_t>(row);
      if (data.sequence[i] >= own) break;
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
      for (int n = 0; n < own; ++n) {
        correct[static_cast<size_t>(n)] +=
            result.by_sequences[static_cast<size_t>(n)].codes == result.truth;
        ++report.selections_by_sequences[static_cast<size_t>(n)];
      }
      dynamic_correct += result.dynamic.codes == result.truth;
    }
    report.selections.push_back(std::move(result));
  }
  const int known = std::max(1, report.selections_with_truth);
  const int choices = data.layout.choices();
  report.chance = 1.0 / choices;
  report.chance_95 = chanceLevel95(choices, report.selections_with_truth);
  for (int n = 0; n < n_max; ++n) {
    const int right = correct[static_cast<size_t>(n)],
              counted = report.selections_by_sequences[static_cast<size_t>(n)];
    report.accuracy.push_back(static_cast<double>(right) / std::max(1, counted));
    report.accuracy_interval.push_back(wilsonInterval(right, counted));
    const double seconds = (n + 1) * data.layout.codes() * data.layout.soa_s;
    report.seconds_per_selection.push_back(seconds);
    report.bits_per_minute.push_back(wolpawBits(choices, report.accuracy.back()) * 60.0 / seconds);
  }
  report.dynamic_accuracy = static_cast<double>(dynamic_correct) / known;
  report.dynamic_accuracy_interval = wilsonInterval(dynamic_correct, report.selections_with_truth);
  report.dynamic_mean_flashes = dynamic_flashes / static_cast<double>(report.selections.size());
  report.dynamic_seconds = report.dynamic_mean_flashes * data.layout.soa_s;
  report.dynamic_bits_per_minute =
      wolpawBits(choices, report.dynamic_accuracy) * 60.0 / report.dynamic_seconds;
  // As recorded: from each selection's first flash to the next one's in the same file.
  double recorded = 0.0;
  int gaps = 0;
  const bool timed = data.sample.size() == data.target.size() && data.info.rate_hz > 0.0;
  for (size_t k = 1; timed && k < data.selections.size(); ++k) {
    const SelectionEpochs &a = data.selections[k - 1], &b = data.selections[k];
    if (a.epochs.empty() || b.epochs.empty() || a.file != b.file) continue;
    recorded += static_cast<double>(data.sample[static_cast<size_t>(b.epochs.front())] -
                                    data.sample[static_cast<size_t>(a.epochs.front())]);
    ++gaps;
  }
  if (gaps > 0) {
    report.recorded_seconds_per_selection = recorded / gaps / data.info.rate_hz;
    report.recorded_bits_per_minute =
        wolpawBits(choices, report.accuracy.back()) * 60.0 / report.recorded_seconds_per_selection;
    report.pause_seconds_per_selection =
        std::max(0.0, report.recorded_seconds_per_selection - report.seconds_per_selection.back());
    for (int n = 0; n < n_max; ++n) {
      const size_t i = static_cast<size_t>(n);
      report.bits_per_minute_with_pauses.push_back(
          wolpawBits(choices, report.accuracy[i]) * 60.0 /
          (report.seconds_per_selection[i] + report.pause_seconds_per_selection));
    }
  }
  return report;
}

std::vector<double> alignScoresPerFile(const P300Dataset& data, std::vector<double>& scores,
                                       const ScoreModel& model) {
  std::vector<double> shifts(data.sources.size(), 0.0);
  if (std::isnan(model.median) || data.file.size() != scores.size()) return shifts;
  for (size_t f = 0; f < data.sources.size(); ++f) {
    std::vector<double> own;
    for (size_t i = 0; i < scores.size(); ++i)
      if (data.file[i] == static_cast<int>(f)) own.push_back(scores[i]);
    if (own.empty()) continue;
    shifts[f] = model.median - median(own);
    for (size_t i = 0; i < scores.size(); ++i)
      if (data.file[i] == static_cast<int>(f)) scores[i] += shifts[f];
  }
  return shifts;
}

std::string foldScheme(const P300Dataset& data, const std::string& requested) {
  int labelled = 0;
  for (const SelectionEpochs& s : data.selections) labelled += !s.target_codes.empty();
  const std::string scheme =
      !requested.empty() ? requested
                         : (!data.codes_are_classes && labelled >= 2 ? "selection" : "block");
  if (scheme == "selection" && labelled < 2) {
    throw std::invalid_argument(
        "cross-validation by selection needs at least 2 selections with known targets, the data "
        "have " +
        std::to_string(labelled) + " (folds by block or by file do not)");
  }
  if (scheme == "file" &&
      (data.sources.size() < 2 || data.file.size() != static_cast<size_t>(data.epochs()))) {
    throw std::invalid_argument("cross-validation by file needs at least 2 files, there is " +
                                std::to_string(data.sources.size()));
  }
  if (scheme == "block" && data.epochs() < 4)
    throw std::invalid_argument("cross-validation by block needs at least 4 epochs, " +
                                std::to_string(data.epochs()) + " are left" +
                                (data.rejected_epochs > 0
                                     ? " (" + std::to_string(data.rejected_epochs) +
                                           " over the rejection limit: raise --reject-uv)"
                                     : std::string()));
  if (scheme != "selection" && scheme != "file" && scheme != "block")
    throw std::invalid_argument("folds by \"" + scheme + "\": must be selection, block or file");
  return scheme;
}

CrossValidation crossValidate(const P300Dataset& data, const TrainingSettings& settings,
                              const Progress& progress) {
  std::vector<int> labelled;
  for (size_t s = 0; s < data.selections.size(); ++s) {
    if (!data.selections[s].target_codes.empty()) labelled.push_back(static_cast<int>(s));
  }
  // Settings the data cannot meet fail now, not in the first fold.
  const ClassifierParts& parts = classifiers().at(settings.method).make;
  if (parts.check) parts.check(withMethodDefaults(settings), data.shape);
  CrossValidation cv;
  cv.folds_by = foldScheme(data, settings.folds_by);
  cv.scores.assign(static_cast<size_t>(data.epochs()), 0.0);
  cv.fold.assign(static_cast<size_t>(data.epochs()), -1);
  std::vector<int> rows;  // the labelled epochs, in time order within each file
  for (int s : labelled) {
    for (int row : data.selections[static_cast<size_t>(s)].epochs) rows.push_back(row);
  }
  std::sort(rows.begin(), rows.end());
  if (cv.folds_by == "selection") {
    cv.folds = std::clamp(settings.folds, 2, static_cast<int>(labelled.size()));
    for (size_t k = 0; k < labelled.size(); ++k) {
      for (int row : data.selections[static_cast<size_t>(labelled[k])].epochs)
        cv.fold[static_cast<size_t>(row)] = static_cast<int>(k * cv.folds / labelled.size());
    }
  } else if (cv.folds_by == "file") {
    cv.folds = static_cast<int>(data.sources.size());
    for (int row : rows) cv.fold[static_cast<size_t>(row)] = data.file[static_cast<size_t>(row)];
  } else {
    cv.folds = std::clamp(settings.folds, 2, std::max(2, static_cast<int>(rows.size()) / 2));
    for (size_t k = 0; k < rows.size(); ++k)
      cv.fold[static_cast<size_t>(rows[k])] = static_cast<int>(k * cv.folds / rows.size());
  }
  for (int fold = 0; fold < cv.folds; ++fold) {
    std::vector<int> train_rows, test_rows;
    for (int row = 0; row < data.epochs(); ++row) {
      const int f = cv.fold[static_cast<size_t>(row)];
      if (f < 0) continue;
      (f == fold ? test_rows : train_rows).push_back(row);
    }
    Eigen::MatrixXd x(static_cast<Eigen::Index>(train_rows.size()), data.features.cols());
    std::vector<bool> y;
    for (size_t i = 0; i < train_rows.size(); ++i) {
      x.row(static_cast<Eigen::Index>(i)) = data.features.row(train_rows[i]);
      y.push_back(data.target[static_cast<size_t>(train_rows[i])]);
    }
    auto classifier = makeClassifier(settings);
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
  std::vector<int> selection, code;
  for (size_t s = 0; s < tested.selections.size(); ++s) {
    for (int row : tested.selections[s].epochs) {
      scored.push_back(cv.scores[static_cast<size_t>(row)]);
      labels.push_back(data.target[static_cast<size_t>(row)]);
      selection.push_back(static_cast<int>(s));
      code.push_back(data.code[static_cast<size_t>(row)]);
    }
  }
  cv.score_model = ScoreModel::fit(scored, labels);
  cv.score_model.rho =
      fitWithinSelectionCorrelation(cv.score_model, scored, labels, selection, code);
  cv.report = evaluateScores(tested, cv.scores, cv.score_model, settings.dynamic);
  return cv;
}

}  // namespace arbci::bci
