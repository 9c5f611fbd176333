// Scores that drift between sessions: a constant offset sums into each code's evidence in
// proportion to its flash count, so with unequal counts the most-flashed code wins whatever the
// subject attended. Aligning each file's median to the training median undoes the offset.
#include <gtest/gtest.h>

#include <random>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/intervals.h"

namespace arbci::bci {
namespace {

// 20 selections among 4 objects; code 1 flashes 3 times as often as the others; targets drawn
// at random. Scores: targets N(1, 1), others N(-1, 1), plus `offset`.
P300Dataset unevenSelections(std::vector<double>& scores, double offset) {
  P300Dataset data;
  data.layout = ParadigmLayout::single(4);
  data.info.rate_hz = 256.0;
  data.sources = {"session 2"};
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int s = 0; s < 20; ++s) {
    const int target = 1 + s % 4;
    SelectionEpochs selection{{}, {target}, 0};
    for (int sequence = 0; sequence < 5; ++sequence) {
      for (int code : {1, 1, 1, 2, 3, 4}) {
        selection.epochs.push_back(static_cast<int>(scores.size()));
        data.target.push_back(code == target);
        data.code.push_back(code);
        data.sequence.push_back(sequence);
        data.selection.push_back(s);
        data.file.push_back(0);
        data.sample.push_back(static_cast<std::int64_t>(scores.size()) * 64);
        scores.push_back((code == target ? 1.0 : -1.0) + noise(random) + offset);
      }
    }
    data.selections.push_back(selection);
  }
  data.features.resize(static_cast<Eigen::Index>(scores.size()), 1);
  return data;
}

TEST(ScoreAlignment, AShiftedSessionSelectsAsWellAsAnUnshiftedOneOnceAligned) {
  ScoreModel trained;  // as fitted on the training session: no offset
  trained.target_mean = 1.0;
  trained.other_mean = -1.0;
  trained.sd = 1.0;
  std::vector<double> reference_scores;
  const P300Dataset reference = unevenSelections(reference_scores, 0.0);
  std::vector<bool> labels(reference.target.begin(), reference.target.end());
  trained.median = ScoreModel::fit(reference_scores, labels).median;
  const StoppingRule fixed{5, 5, 0.0};
  const EvaluationReport unshifted = evaluateScores(reference, reference_scores, trained, fixed);

  std::vector<double> scores;
  const P300Dataset shifted = unevenSelections(scores, 3.0);
  const EvaluationReport raw = evaluateScores(shifted, scores, trained, fixed);
  EXPECT_NEAR(raw.auc, unshifted.auc, 1e-12);  // a shift does not change the ranking
  // Unaligned, code 1 (15 flashes to the others' 5) collects the offset: it wins every selection.
  EXPECT_LE(raw.accuracy.back(), 0.3);
  const std::vector<double> shifts = alignScoresPerFile(shifted, scores, trained);
  ASSERT_EQ(shifts.size(), 1u);
  EXPECT_NEAR(shifts[0], -3.0, 0.3);
  const EvaluationReport aligned = evaluateScores(shifted, scores, trained, fixed);
  EXPECT_NEAR(aligned.accuracy.back(), unshifted.accuracy.back(), 0.1);
  EXPECT_GE(aligned.accuracy.back(), 0.9);
}

TEST(Intervals, KnownValues) {
  // Wilson: 8 of 10 -> [0.490, 0.943]; Hanley & McNeil: AUC 0.9, 50 + 50 -> SE 0.0321.
  const Interval w = wilsonInterval(8, 10);
  EXPECT_NEAR(w.low, 0.490, 0.001);
  EXPECT_NEAR(w.high, 0.943, 0.001);
  const Interval a = aucInterval(0.9, 50, 50);
  EXPECT_NEAR((a.high - a.low) / (2 * 1.96), 0.0321, 0.0005);
  // Binomial: among 4 choices over 20 selections, 10 right has p = 0.014, 9 right p = 0.041,
  // 8 right p = 0.102: 9 of 20 (0.45) is the first accuracy that beats guessing at 5 %.
  EXPECT_NEAR(chanceLevel95(4, 20), 0.45, 1e-12);
}

}  // namespace
}  // namespace arbci::bci
