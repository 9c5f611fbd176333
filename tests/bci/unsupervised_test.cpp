// Learning the P300 without labels, on generated epochs whose class means are known: the fit
// decodes every selection's attended stimulus, the labels it finds give back the class means,
// its learning curve settles, and data with no single attended stimulus among several is
// refused with the reason.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Cholesky>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/unsupervised.h"

namespace arbci::bci {
namespace {

// `selections` selections of 4 single stimuli, `sequences` sequences each, `p` features: a
// target epoch is the non-target mean plus `shift` along a fixed direction, all with unit noise.
P300Dataset generated(int selections, int sequences, int p, double shift, std::uint64_t seed,
                      Eigen::VectorXd& direction) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal;
  direction = Eigen::VectorXd::Zero(p);
  for (int i = 0; i < p; ++i) direction[i] = normal(random);
  direction.normalize();
  P300Dataset d;
  d.layout = ParadigmLayout::single(4);
  const int n = selections * sequences * 4;
  d.features.resize(n, p);
  int row = 0;
  std::uniform_int_distribution<int> pick(1, 4);
  for (int s = 0; s < selections; ++s) {
    const int attended = pick(random);
    d.selections.push_back({{}, {attended}, 0});
    for (int q = 0; q < sequences; ++q) {
      for (int code = 1; code <= 4; ++code, ++row) {
        for (int i = 0; i < p; ++i) d.features(row, i) = normal(random);
        const bool target = code == attended;
        if (target) d.features.row(row) += shift * direction.transpose();
        d.target.push_back(target);
        d.code.push_back(code);
        d.sequence.push_back(q);
        d.selection.push_back(s);
        d.selections.back().epochs.push_back(row);
      }
    }
  }
  return d;
}

TEST(Unsupervised, DecodesEverySelectionAndRecoversTheClassMeans) {
  Eigen::VectorXd direction;
  const P300Dataset data = generated(20, 10, 12, 1.5, 5, direction);
  UnsupervisedOptions options;
  const UnsupervisedFit fit = fitWithoutLabels(data, {}, options);
  ASSERT_EQ(fit.choice.size(), 20u);
  int right = 0;
  for (size_t k = 0; k < fit.choice.size(); ++k)
    right += data.layout.codesOf(fit.choice[k]) == data.selections[k].target_codes;
  EXPECT_GE(right, 19);
  EXPECT_GE(fit.agreeing, 2);
  // The labels found give back the class means: target minus non-target along the direction.
  const P300Dataset found = withLabelsFound(data, fit);
  Eigen::VectorXd target = Eigen::VectorXd::Zero(12), other = Eigen::VectorXd::Zero(12);
  int nt = 0, no = 0;
  for (int e = 0; e < found.epochs(); ++e) {
    if (found.target[static_cast<size_t>(e)]) {
      target += found.features.row(e).transpose();
      ++nt;
    } else {
      other += found.features.row(e).transpose();
      ++no;
    }
  }
  const Eigen::VectorXd difference = target / nt - other / no;
  EXPECT_NEAR(difference.dot(direction), 1.5, 0.2);
  EXPECT_LT((difference - 1.5 * direction).norm(), 0.6);
}

TEST(Unsupervised, TheLearningCurveSettlesAndTheAucMatchesTheTruth) {
  Eigen::VectorXd direction;
  const P300Dataset data = generated(12, 8, 12, 1.5, 9, direction);
  const UnsupervisedReport report = evaluateWithoutLabels(data);
  ASSERT_TRUE(report.labelled);
  EXPECT_GE(report.right, 11);
  ASSERT_EQ(report.curve.size(), 12u);
  int late = 0;
  for (size_t k = 6; k < report.curve.size(); ++k) late += report.curve[k].right;
  EXPECT_GE(late, 5);
  // Held out, it separates the true classes about as well as LDA on the true labels does, each
  // selection scored by the class means of the others.
  std::vector<double> scores;
  std::vector<bool> target;
  for (size_t k = 0; k < data.selections.size(); ++k) {
    Eigen::VectorXd mt = Eigen::VectorXd::Zero(12), mo = Eigen::VectorXd::Zero(12);
    Eigen::MatrixXd x(0, 12);
    int nt = 0, no = 0;
    for (size_t j = 0; j < data.selections.size(); ++j) {
      if (j == k) continue;
      for (int e : data.selections[j].epochs) {
        x.conservativeResize(x.rows() + 1, Eigen::NoChange);
        x.row(x.rows() - 1) = data.features.row(e);
        if (data.target[static_cast<size_t>(e)]) {
          mt += data.features.row(e).transpose();
          ++nt;
        } else {
          mo += data.features.row(e).transpose();
          ++no;
        }
      }
    }
    const Eigen::MatrixXd centred = x.rowwise() - x.colwise().mean();
    const Eigen::MatrixXd covariance =
        centred.transpose() * centred / static_cast<double>(x.rows());
    const Eigen::VectorXd w = covariance.ldlt().solve(mt / nt - mo / no);
    for (int e : data.selections[k].epochs) {
      scores.push_back(data.features.row(e).dot(w));
      target.push_back(data.target[static_cast<size_t>(e)]);
    }
  }
  const double supervised = areaUnderCurve(scores, target);
  EXPECT_NEAR(report.cross_validated_auc, supervised, 0.05);
}

TEST(Unsupervised, AResponseBeatsTheShuffledCodesAndGeneralisesHeldOut) {
  // With a response, a fit without any one selection decodes it as the whole fit does, and the
  // fit explains more variance than any fit with each selection's codes shuffled.
  Eigen::VectorXd direction;
  const UnsupervisedFit signal = fitWithoutLabels(generated(16, 8, 12, 1.5, 21, direction));
  EXPECT_GE(signal.consistency, 0.9);
  EXPECT_EQ(signal.beats_shuffled, 9);
  // Noise alone: with many selections a fit of it can be as stable without any one selection,
  // but it explains no more than fits of the same data with the codes shuffled.
  const UnsupervisedFit noise = fitWithoutLabels(generated(16, 8, 12, 0.0, 21, direction));
  EXPECT_LT(noise.beats_shuffled, 9);
}

TEST(Unsupervised, HeldOutRefitsKeepTheSignTheP300IsKnownToHave) {
  // Few selections of a weak response: fits again without a selection may settle on the mirror
  // solution. Told the response's sign, they keep a start with that sign; told the opposite one,
  // they keep mirrors, and the P300's decoding no longer looks consistent.
  Eigen::VectorXd direction;
  const P300Dataset data = generated(8, 8, 12, 1.0, 33, direction);
  const auto run = [&](double sign) {
    UnsupervisedOptions options;
    options.p300_direction = sign * direction;
    const UnsupervisedFit fit = fitWithoutLabels(data, {}, options);
    int right = 0;
    for (size_t k = 0; k < fit.choice.size(); ++k)
      right += data.layout.codesOf(fit.choice[k]) == data.selections[k].target_codes;
    return std::pair{right, fit.consistency};
  };
  const auto [right, consistency] = run(1.0);
  EXPECT_GE(right, 7);
  EXPECT_GE(consistency, 0.85);
  const auto [right_against, consistency_against] = run(-1.0);
  EXPECT_TRUE(right_against < right || consistency_against < 0.5)
      << right_against << " right, consistency " << consistency_against;
}

TEST(Unsupervised, AStartFromTheTextbookP300FindsAWeakResponseInFewSelections) {
  // Five selections of a weak response: random starts often settle on a labelling of noise. The
  // textbook P300 is only roughly the subject's (here: the true direction with as much again of
  // another, random one), and still a start from it finds the response more often.
  int with = 0, without = 0;
  for (std::uint64_t seed = 100; seed < 120; ++seed) {
    Eigen::VectorXd direction;
    const P300Dataset data = generated(5, 6, 12, 0.8, seed, direction);
    Eigen::VectorXd rough = Eigen::VectorXd::Zero(direction.size());
    std::mt19937_64 random(seed + 1000);
    std::normal_distribution<double> normal;
    for (Eigen::Index i = 0; i < rough.size(); ++i) rough[i] = normal(random);
    rough = direction + rough.normalized();
    const auto right = [&](const UnsupervisedOptions& options) {
      const UnsupervisedFit fit = fitWithoutLabels(data, {}, options);
      int n = 0;
      for (size_t k = 0; k < fit.choice.size(); ++k)
        n += data.layout.codesOf(fit.choice[k]) == data.selections[k].target_codes;
      return n;
    };
    UnsupervisedOptions options;
    options.shuffles = 0;
    without += right(options);
    options.p300_direction = rough;
    with += right(options);
  }
  EXPECT_GT(with, without) << with << " vs " << without << " of 100";
}

TEST(Unsupervised, KnownSelectionsAreHeldAndAChoiceNotFlashedIsNeverDecoded) {
  Eigen::VectorXd direction;
  P300Dataset data = generated(10, 6, 8, 1.5, 4, direction);
  // Selection 1's choice given (wrongly on purpose): the fit keeps it.
  const int truth = *data.selections[0].target_codes.begin() - 1;
  UnsupervisedOptions options;
  options.known[0] = (truth + 1) % 4;
  options.held_out = false;
  EXPECT_EQ(fitWithoutLabels(data, {}, options).choice[0], (truth + 1) % 4);
  // Selection 2's attended stimulus never flashed (its object out of view): another is decoded.
  const int attended = *data.selections[1].target_codes.begin();
  std::vector<int> kept;
  for (int e : data.selections[1].epochs)
    if (data.code[static_cast<size_t>(e)] != attended) kept.push_back(e);
  data.selections[1].epochs = kept;
  EXPECT_NE(fitWithoutLabels(data, {}, options).choice[1], attended - 1);
}

TEST(Unsupervised, DataWithNoSingleAttendedStimulusAmongSeveralIsRefused) {
  Eigen::VectorXd direction;
  P300Dataset data = generated(4, 4, 6, 1.0, 3, direction);
  // The third selection flashes one stimulus only: nothing to choose between.
  for (int e : data.selections[2].epochs) data.code[static_cast<size_t>(e)] = 1;
  try {
    fitWithoutLabels(data);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("selection 3 flashes 1 whole choice"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace arbci::bci
