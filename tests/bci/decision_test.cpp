// A selection's certainty against computations made another way: the posterior of a selection
// with a code withheld for two sequences equals the one written out from the likelihood of every
// flash (independent, and with the scores of a code correlated within the selection), its claims
// hold over many simulated selections, and the correlation is found again from scores drawn with
// it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "arbci/bci/decision.h"

namespace arbci::bci {
namespace {

struct Flash {
  int code;
  double score;
};

// One selection of 4 objects, `sequences` sequences, object `target` attended; object 3 withheld
// (not shown) in the first two sequences. Each code's scores share a draw of correlation `rho`.
std::vector<Flash> drawSelection(std::mt19937_64& random, const ScoreModel& m, int target,
                                 int sequences, double rho) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Flash> flashes;
  double shared[5];
  for (double& s : shared) s = normal(random);
  for (int q = 0; q < sequences; ++q) {
    for (int code = 1; code <= 4; ++code) {
      if (code == 3 && q < 2) continue;
      const double noise = std::sqrt(rho) * shared[code] + std::sqrt(1.0 - rho) * normal(random);
      flashes.push_back({code, (code == target ? m.target_mean : m.other_mean) + m.sd * noise});
    }
  }
  return flashes;
}

// The posterior of each object written out: the log-likelihood of all the flashes under "object
// c is attended", every code's scores jointly normal with the within-selection correlation.
std::vector<double> posteriorByHand(const std::vector<Flash>& flashes, const ScoreModel& m) {
  std::vector<double> log_likelihood(5, 0.0);
  for (int c = 1; c <= 4; ++c) {
    for (int code = 1; code <= 4; ++code) {
      std::vector<double> x;
      for (const Flash& f : flashes)
        if (f.code == code) x.push_back(f.score - (code == c ? m.target_mean : m.other_mean));
      const auto n = static_cast<Eigen::Index>(x.size());
      Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(n, n, m.rho * m.sd * m.sd);
      cov.diagonal().setConstant(m.sd * m.sd);
      const Eigen::VectorXd r = Eigen::Map<Eigen::VectorXd>(x.data(), n);
      log_likelihood[static_cast<size_t>(c)] += -0.5 * r.dot(cov.ldlt().solve(r));
    }
  }
  double top = -1e300, total = 0.0;
  for (int c = 1; c <= 4; ++c) top = std::max(top, log_likelihood[static_cast<size_t>(c)]);
  std::vector<double> p(5, 0.0);
  for (int c = 1; c <= 4; ++c)
    total += p[static_cast<size_t>(c)] = std::exp(log_likelihood[static_cast<size_t>(c)] - top);
  for (double& v : p) v /= total;
  return p;
}

Decision accumulate(const std::vector<Flash>& flashes, const ScoreModel& m) {
  SelectionAccumulator a(ParadigmLayout::single(4), m);
  for (const Flash& f : flashes) a.add(f.code, f.score);
  return a.decide();
}

TEST(SelectionCertainty, AWithheldObjectWeighsWhatItsFlashesSayWrittenOutTwoWays) {
  std::mt19937_64 random(11);
  for (const double rho : {0.0, 0.08}) {
    ScoreModel m{0.8, -0.3, 1.1};
    m.rho = rho;
    for (int repeat = 0; repeat < 20; ++repeat) {
      const std::vector<Flash> flashes = drawSelection(random, m, 2, 8, rho);
      const Decision d = accumulate(flashes, m);
      const std::vector<double> p = posteriorByHand(flashes, m);
      EXPECT_EQ(d.flashes.at(3), 6);
      EXPECT_EQ(d.flashes.at(1), 8);
      const int chosen = *d.codes.begin();
      EXPECT_NEAR(d.certainty, p[static_cast<size_t>(chosen)], 1e-9) << "rho " << rho;
      for (int c = 1; c <= 4; ++c) EXPECT_LE(p[static_cast<size_t>(c)], d.certainty + 1e-9);
    }
  }
}

// Over many selections whose object 3 was withheld for two sequences, the wrong decisions are as
// many as the certainties claim (the withheld object gains nothing it should not), with and
// without correlated scores.
TEST(SelectionCertainty, ItsClaimsHoldWhenAnObjectWasWithheld) {
  std::mt19937_64 random(12);
  for (const double rho : {0.0, 0.08}) {
    ScoreModel m{0.5, -0.2, 1.0};
    m.rho = rho;
    double expected = 0.0, variance = 0.0;
    int wrong = 0, withheld_chosen_wrongly = 0;
    double withheld_expected = 0.0;
    for (int n = 0; n < 4000; ++n) {
      const int target = 1 + n % 4;
      const Decision d = accumulate(drawSelection(random, m, target, 5, rho), m);
      const int chosen = *d.codes.begin();
      expected += 1.0 - d.certainty;
      variance += d.certainty * (1.0 - d.certainty);
      wrong += chosen != target;
      if (chosen == 3 && target != 3) ++withheld_chosen_wrongly;
      if (chosen == 3) withheld_expected += 1.0 - d.certainty;
    }
    EXPECT_NEAR(wrong, expected, 4.0 * std::sqrt(variance)) << "rho " << rho;
    EXPECT_LE(withheld_chosen_wrongly, withheld_expected + 4.0 * std::sqrt(withheld_expected + 1.0))
        << "rho " << rho;
  }
}

TEST(SelectionCertainty, TheCorrelationWithinASelectionIsFoundFromItsScores) {
  std::mt19937_64 random(13);
  for (const double rho : {0.0, 0.1, 0.25}) {
    ScoreModel m{1.0, 0.0, 1.0};
    std::vector<double> scores;
    std::vector<bool> target;
    std::vector<int> selection, code;
    for (int s = 0; s < 400; ++s) {
      for (const Flash& f : drawSelection(random, m, 1 + s % 4, 8, rho)) {
        scores.push_back(f.score + 0.3 * (s % 7));  // what a selection shares cancels
        target.push_back(f.code == 1 + s % 4);
        selection.push_back(s);
        code.push_back(f.code);
      }
    }
    // The class means as fitted would take up the shared shift: fit with them.
    const ScoreModel fitted = ScoreModel::fit(scores, target);
    EXPECT_NEAR(fitWithinSelectionCorrelation(fitted, scores, target, selection, code), rho, 0.03)
        << "rho " << rho;
  }
}

}  // namespace
}  // namespace arbci::bci
