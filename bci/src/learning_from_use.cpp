#include "arbci/bci/learning_from_use.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/p300_template.h"

namespace arbci::bci {
namespace {

// The dataset's selections regrouped by the caller's numbers: a pause within a selection (a gap
// in its flashes) must not split it in two, as buildDataset's grouping by gaps would.
void groupByNumber(P300Dataset& data, const Recording& recording,
                   const std::vector<int>& number_of_stimulus, const std::map<int, int>& known,
                   std::vector<int>& numbers, std::map<int, int>& known_index) {
  std::map<std::int64_t, int> number_at;
  for (size_t i = 0; i < recording.stimuli.size(); ++i)
    number_at[recording.stimuli[i].sample] = number_of_stimulus.at(i);
  std::map<int, int> index_of;
  data.selections.clear();
  for (int e = 0; e < data.epochs(); ++e) {
    const int number = number_at.at(data.sample[static_cast<size_t>(e)]);
    auto [at, added] = index_of.emplace(number, static_cast<int>(data.selections.size()));
    if (added) {
      data.selections.push_back({});
      numbers.push_back(number);
    }
    SelectionEpochs& selection = data.selections[static_cast<size_t>(at->second)];
    selection.epochs.push_back(e);
    data.selection[static_cast<size_t>(e)] = at->second;
    if (data.target[static_cast<size_t>(e)]) selection.target_codes.insert(data.code[e]);
  }
  for (const auto& [number, choice] : known) {
    const auto found = index_of.find(number);
    if (found != index_of.end()) known_index[found->second] = choice;
  }
}

// `data` with only `keep`'s selections (in that order), for training on those fitted alone.
P300Dataset onlySelections(const P300Dataset& data, const std::vector<int>& keep) {
  P300Dataset out = data;
  out.selections.clear();
  out.target.clear();
  out.code.clear();
  out.sequence.clear();
  out.selection.clear();
  out.file.clear();
  out.sample.clear();
  std::vector<int> rows;
  for (int s : keep) {
    SelectionEpochs selection = data.selections[static_cast<size_t>(s)];
    for (int& e : selection.epochs) {
      const auto i = static_cast<size_t>(e);
      out.target.push_back(data.target[i]);
      out.code.push_back(data.code[i]);
      out.sequence.push_back(data.sequence[i]);
      out.selection.push_back(static_cast<int>(out.selections.size()));
      out.file.push_back(data.file[i]);
      out.sample.push_back(data.sample[i]);
      rows.push_back(e);
      e = static_cast<int>(rows.size()) - 1;
    }
    out.selections.push_back(std::move(selection));
  }
  out.features.resize(static_cast<Eigen::Index>(rows.size()), data.features.cols());
  for (size_t r = 0; r < rows.size(); ++r)
    out.features.row(static_cast<Eigen::Index>(r)) = data.features.row(rows[r]);
  return out;
}

}  // namespace

LearnedSelections learnFromUse(const Recording& recording,
                               const std::vector<int>& number_of_stimulus,
                               const std::map<int, int>& known, const std::map<int, int>& previous,
                               const PipelineSettings& pipeline, const TrainingSettings& training,
                               const UnsupervisedOptions& options) {
  DatasetOptions dataset;
  dataset.keep_unknown = true;
  P300Dataset data = buildDataset({recording}, pipeline, {}, dataset);
  LearnedSelections out;
  UnsupervisedOptions em = options;
  em.known.clear();
  em.initial.clear();
  groupByNumber(data, recording, number_of_stimulus, known, out.numbers, em.known);
  // Only selections flashing at least two whole choices can be learnt from (a selection cut
  // short before its first whole sequence cannot).
  std::vector<int> usable;
  std::vector<int> numbers;
  for (size_t s = 0; s < data.selections.size(); ++s) {
    std::set<int> seen;
    for (int e : data.selections[s].epochs) seen.insert(data.code[static_cast<size_t>(e)]);
    int whole = 0;
    for (int c = 0; c < data.layout.choices(); ++c) {
      const std::set<int> codes = data.layout.codesOf(c);
      whole += std::includes(seen.begin(), seen.end(), codes.begin(), codes.end());
    }
    if (whole >= 2) {
      usable.push_back(static_cast<int>(s));
      numbers.push_back(out.numbers[s]);
    }
  }
  for (size_t k = 0; k < numbers.size(); ++k) {
    const auto before = previous.find(numbers[k]);
    if (before != previous.end()) em.initial[usable[k]] = before->second;
  }
  if (usable.empty())
    throw std::invalid_argument("no selection yet flashes two whole choices to learn from");
  if (em.p300_direction.size() == 0) em.p300_direction = p300Template(pipeline, data.info);
  const UnsupervisedFit fit = fitWithoutLabels(data, usable, em);
  out.numbers = numbers;
  out.choice = fit.choice;
  out.posterior = fit.posterior;
  out.agreeing = fit.agreeing;
  out.restarts = fit.restarts;
  out.consistency = fit.consistency;
  out.explained = fit.explained;
  out.shuffled_explained = fit.shuffled_explained;
  out.beats_shuffled = fit.beats_shuffled;
  out.shuffles = em.shuffles;
  out.p3_uv = fit.p300_uv;
  // Only the selections fitted go into training.
  const P300Dataset found = onlySelections(withLabelsFound(data, fit), usable);
  TrainingResult result = trainModel(found, pipeline, training);
  out.model = std::move(result.model);
  return out;
}

std::map<int, int> decodeSelections(const P300Model& model, const Recording& recording,
                                    const std::vector<int>& number_of_stimulus,
                                    const PipelineSettings& pipeline) {
  DatasetOptions dataset;
  dataset.keep_unknown = true;
  P300Dataset data = buildDataset({recording}, pipeline, {}, dataset);
  std::vector<int> numbers;
  std::map<int, int> unused;
  groupByNumber(data, recording, number_of_stimulus, {}, numbers, unused);
  std::map<int, int> out;
  for (size_t s = 0; s < data.selections.size(); ++s) {
    std::map<int, double> sum;
    for (int e : data.selections[s].epochs)
      sum[data.code[static_cast<size_t>(e)]] += model.classifier->score(data.features.row(e));
    double best = -1e300;
    int code = 0;
    for (int c = 0; c < data.layout.choices(); ++c) {
      const std::set<int> codes = data.layout.codesOf(c);
      double v = 0.0;
      bool whole = true;
      for (int k : codes) {
        const auto found = sum.find(k);
        whole = whole && found != sum.end();
        if (found != sum.end()) v += found->second;
      }
      if (whole && v > best) {
        best = v;
        code = *codes.begin();
      }
    }
    if (code > 0) out[numbers[s]] = code;
  }
  return out;
}

Trust judgeTrust(const LearnedSelections& fit, const std::map<int, int>& previous_choices,
                 const TrustRule& rule) {
  Trust trust;
  const int n = static_cast<int>(fit.numbers.size());
  std::vector<std::string> missing;
  if (n < rule.min_selections)
    missing.push_back(std::to_string(rule.min_selections - n) + " more selection" +
                      (rule.min_selections - n == 1 ? "" : "s"));
  if (fit.beats_shuffled < fit.shuffles) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "a response that follows the flashes: so far the EEG fits the objects as "
                  "flashed no better than with the flashes' order shuffled (beaten in %d of %d "
                  "shuffles; fit %.3f against up to %.3f)",
                  fit.beats_shuffled, fit.shuffles, fit.explained, fit.shuffled_explained);
    missing.push_back(text);
  }
  if (fit.p3_uv && *fit.p3_uv <= 0.0) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "a positive P300 (by the labels found, target minus non-target along a textbook "
                  "P300 at the parietal sites is %.2f uV: the mirror of the response)",
                  *fit.p3_uv);
    missing.push_back(text);
  }
  if (fit.consistency < rule.min_consistency) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "selections that decode the same when left out of the fit: %d of %d do (%.2f), "
                  "%.2f needed",
                  static_cast<int>(std::lround(fit.consistency * n)), n, fit.consistency,
                  rule.min_consistency);
    missing.push_back(text);
  }
  int compared = 0;
  for (size_t k = 0; k < fit.numbers.size(); ++k) {
    const auto before = previous_choices.find(fit.numbers[k]);
    if (before == previous_choices.end()) continue;
    ++compared;
    if (before->second != fit.choice[k]) trust.changed.push_back(fit.numbers[k]);
  }
  // A tenth of the selections compared may change, and one always may: a selection the subject
  // attended weakly can flip between two choices from fit to fit however settled the model is;
  // two changing and more than a tenth show a fit that has not settled.
  const double allowed = std::max(1.0, 0.1 * static_cast<double>(compared));
  if (static_cast<double>(trust.changed.size()) > allowed) {
    std::string list;
    for (int number : trust.changed) list += (list.empty() ? "" : ", ") + std::to_string(number);
    missing.push_back("a fit that keeps its decoding of the earlier selections (changed: " + list +
                      ")");
  }
  trust.trusted = missing.empty();
  for (const std::string& m : missing)
    trust.waiting_for += (trust.waiting_for.empty() ? "" : "; ") + m;
  return trust;
}

}  // namespace arbci::bci
