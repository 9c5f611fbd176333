// The separation a learnt classifier may claim, from selections scored by models that had not
// seen them: found without their labels, it is about the true one where there is a response and
// far below what taking each selection's highest code as its target gives where there is none;
// rows and columns are each a group with one attended code; and a score model bounded by it
// keeps its midpoint and spread, so its decisions are as sure as that separation allows.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "arbci/bci/held_out_separation.h"

namespace arbci::bci {
namespace {

// `selections` of `codes` single stimuli flashed `flashes` times each, standard normal scores
// with the attended one's shifted by `separation`.
std::vector<HeldOutSelection> generated(int selections, int codes, int flashes, double separation,
                                        std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise;
  std::uniform_int_distribution<int> pick(1, codes);
  std::vector<HeldOutSelection> out(static_cast<size_t>(selections));
  for (HeldOutSelection& s : out) {
    const int attended = pick(random);
    for (int f = 0; f < flashes; ++f) {
      for (int code = 1; code <= codes; ++code) {
        s.code.push_back(code);
        s.z.push_back(noise(random) + (code == attended ? separation : 0.0));
      }
    }
  }
  return out;
}

// Each selection's highest-scoring code taken as its target: the separation that choice shows.
double hardChoiceSeparation(const std::vector<HeldOutSelection>& selections, int codes) {
  std::vector<double> target, other;
  for (const HeldOutSelection& s : selections) {
    std::vector<double> sum(static_cast<size_t>(codes) + 1, 0.0);
    for (size_t i = 0; i < s.code.size(); ++i) sum[static_cast<size_t>(s.code[i])] += s.z[i];
    int best = 1;
    for (int c = 2; c <= codes; ++c) best = sum[c] > sum[best] ? c : best;
    for (size_t i = 0; i < s.code.size(); ++i)
      (s.code[i] == best ? target : other).push_back(s.z[i]);
  }
  auto mean = [](const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) m += x;
    return m / static_cast<double>(v.size());
  };
  const double mt = mean(target), mo = mean(other);
  double squares = 0.0;
  for (double x : target) squares += (x - mt) * (x - mt);
  for (double x : other) squares += (x - mo) * (x - mo);
  return (mt - mo) / std::sqrt(squares / static_cast<double>(target.size() + other.size()));
}

TEST(HeldOutSeparation, AResponseIsMeasuredAsItIs) {
  const auto selections = generated(30, 4, 16, 1.0, 7);
  const std::optional<double> found = heldOutSeparation(selections, ParadigmLayout::single(4));
  ASSERT_TRUE(found.has_value());
  EXPECT_NEAR(*found, 1.0, 0.15);
}

TEST(HeldOutSeparation, NoResponseIsNotMistakenForOneAsTheHighestCodesWouldBe) {
  // Over 20 draws of 10 selections: on noise, no code is attended more than another.
  double found_sum = 0.0, hard_sum = 0.0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto selections = generated(10, 4, 16, 0.0, seed);
    const std::optional<double> found = heldOutSeparation(selections, ParadigmLayout::single(4));
    ASSERT_TRUE(found.has_value());
    found_sum += *found;
    hard_sum += hardChoiceSeparation(selections, 4);
  }
  EXPECT_LT(found_sum, 0.5 * hard_sum);
}

TEST(HeldOutSeparation, RowsAndColumnsEachHaveOneAttendedCode) {
  // A 3 x 3 matrix: codes 1-3 rows, 4-6 columns; row 2 and column 6 attended in every selection.
  std::mt19937_64 random(3);
  std::normal_distribution<double> noise;
  std::vector<HeldOutSelection> selections(20);
  for (HeldOutSelection& s : selections) {
    for (int f = 0; f < 12; ++f) {
      for (int code = 1; code <= 6; ++code) {
        s.code.push_back(code);
        s.z.push_back(noise(random) + (code == 2 || code == 6 ? 1.0 : 0.0));
      }
    }
  }
  const std::optional<double> found = heldOutSeparation(selections, ParadigmLayout::matrix(3, 3));
  ASSERT_TRUE(found.has_value());
  EXPECT_NEAR(*found, 1.0, 0.15);
}

TEST(HeldOutSeparation, NothingToMeasureWithoutTwoCodesFlashed) {
  EXPECT_FALSE(heldOutSeparation({}, ParadigmLayout::single(4)).has_value());
  HeldOutSelection one_code;
  one_code.code = {2, 2, 2};
  one_code.z = {0.1, 0.4, -0.2};
  EXPECT_FALSE(heldOutSeparation({one_code}, ParadigmLayout::single(4)).has_value());
}

TEST(HeldOutSeparation, ABoundedScoreModelKeepsItsMidpointAndSpreadAndClaimsLess) {
  ScoreModel fitted;
  fitted.target_mean = 3.0;
  fitted.other_mean = -1.0;
  fitted.sd = 2.0;  // separation 2
  fitted.median = -0.5;
  const ScoreModel bounded = boundSeparation(fitted, 0.5);
  EXPECT_DOUBLE_EQ(bounded.target_mean + bounded.other_mean, 2.0);
  EXPECT_DOUBLE_EQ(bounded.sd, 2.0);
  EXPECT_DOUBLE_EQ(bounded.separation(), 0.5);
  EXPECT_DOUBLE_EQ(bounded.median, -0.5);
  EXPECT_DOUBLE_EQ(standardised(bounded, 1.0), standardised(fitted, 1.0));
  // A larger separation than the fit's changes nothing.
  EXPECT_DOUBLE_EQ(boundSeparation(fitted, 3.0).target_mean, 3.0);
  // The same scores, less sure under the bounded model; none at all at zero.
  SelectionAccumulator sure(ParadigmLayout::single(4), fitted),
      bounded_sure(ParadigmLayout::single(4), bounded),
      none(ParadigmLayout::single(4), boundSeparation(fitted, -0.3));
  for (int flash = 0; flash < 8; ++flash) {
    for (int code = 1; code <= 4; ++code) {
      const double score = code == 3 ? 2.0 : 0.5;
      sure.add(code, score);
      bounded_sure.add(code, score);
      none.add(code, score);
    }
  }
  EXPECT_EQ(bounded_sure.decide().codes, std::set<int>{3});
  EXPECT_GT(sure.decide().certainty, 0.999);
  EXPECT_LT(bounded_sure.decide().certainty, 0.9);
  EXPECT_NEAR(none.decide().certainty, 0.25, 1e-9);
}

}  // namespace
}  // namespace arbci::bci
