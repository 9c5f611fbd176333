// Selection figures from runs with selections cut short: a retake or the end of a run leaves a
// selection with fewer whole sequences than the others, or none. Each counts with what it has;
// one short selection never sinks the others (it used to set the run's number of sequences to its
// own, and a fragment made the whole run "no selection has a whole sequence"), and one longer
// selection does not set it either.
#include <gtest/gtest.h>

#include <stdexcept>

#include "arbci/bci/evaluation.h"

namespace arbci::bci {
namespace {

// Selections among 4 objects, each flashed once a sequence; `flashes[s]` flashes of selection s
// (4 a whole sequence). Targets score 1, the others -1.
P300Dataset selectionsOf(const std::vector<int>& flashes, std::vector<double>& scores) {
  P300Dataset data;
  data.layout = ParadigmLayout::single(4);
  data.info.rate_hz = 256.0;
  data.sources = {"run"};
  for (size_t s = 0; s < flashes.size(); ++s) {
    const int target = 1 + static_cast<int>(s) % 4;
    SelectionEpochs selection{{}, {target}, 0};
    for (int k = 0; k < flashes[s]; ++k) {
      const int code = 1 + k % 4;
      selection.epochs.push_back(static_cast<int>(scores.size()));
      data.target.push_back(code == target);
      data.code.push_back(code);
      data.sequence.push_back(k / 4);
      data.selection.push_back(static_cast<int>(s));
      data.file.push_back(0);
      data.sample.push_back(static_cast<std::int64_t>(scores.size()) * 64);
      scores.push_back(code == target ? 1.0 : -1.0);
    }
    data.selections.push_back(selection);
  }
  data.features.resize(static_cast<Eigen::Index>(scores.size()), 1);
  return data;
}

ScoreModel unitModel() {
  ScoreModel model;
  model.target_mean = 1.0;
  model.other_mean = -1.0;
  model.sd = 1.0;
  return model;
}

TEST(Evaluation, ASelectionCutShortCountsWithTheSequencesItHasAndAFragmentIsLeftOut) {
  std::vector<double> scores;
  // Four whole selections of 5 sequences, one cut after 2 sequences and a flash, one fragment,
  // one that ran on to 9 sequences (scored up to the run's 5).
  const P300Dataset data = selectionsOf({20, 20, 9, 20, 2, 20, 36}, scores);
  const EvaluationReport report =
      evaluateScores(data, scores, unitModel(), StoppingRule{5, 2, 0.0});
  EXPECT_EQ(report.max_sequences, 5);
  EXPECT_EQ(report.fragments, 1);
  EXPECT_EQ(report.selections.size(), 6u);
  EXPECT_EQ(report.selections_with_truth, 6);
  EXPECT_EQ(report.selections_by_sequences, (std::vector<int>{6, 6, 5, 5, 5}));
  ASSERT_EQ(report.accuracy.size(), 5u);
  for (double a : report.accuracy) EXPECT_DOUBLE_EQ(a, 1.0);
  EXPECT_EQ(report.selections[2].by_sequences.size(), 2u);
  // The short selection's choice after 5 sequences is its last (after 2).
  EXPECT_EQ(report.selections[5].by_sequences.size(), 5u);
  EXPECT_EQ(report.selected(5), "object 1, object 2, object 3, object 4, object 2, object 3");
}

TEST(Evaluation, WithoutAnyWholeSequenceTheRunIsRefusedSayingSo) {
  std::vector<double> scores;
  const P300Dataset data = selectionsOf({3, 2}, scores);
  try {
    evaluateScores(data, scores, unitModel(), StoppingRule{5, 2, 0.0});
    FAIL() << "no selection has a whole sequence, yet the run was scored";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "no selection has a whole sequence");
  }
}

}  // namespace
}  // namespace arbci::bci
