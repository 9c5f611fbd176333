// Whether the arm may act on a model learnt from use: enough selections, a leave-one-out
// consistency at least the minimum, and a decoding of the earlier selections that the new fit kept;
// what is missing is said in words.
#include <gtest/gtest.h>

#include "arbci/bci/features.h"
#include "arbci/bci/learning_from_use.h"
#include "arbci/bci/p300_template.h"

namespace arbci::bci {
namespace {

LearnedSelections fitOf(int selections, double consistency) {
  LearnedSelections fit;
  for (int k = 1; k <= selections; ++k) {
    fit.numbers.push_back(2 * k);  // the session's numbers, not 1..n
    fit.choice.push_back(k % 4);
  }
  fit.consistency = consistency;
  fit.restarts = 12;
  fit.explained = 0.02;
  fit.shuffled_explained = 0.01;
  fit.beats_shuffled = fit.shuffles = 9;
  return fit;
}

std::map<int, int> decodings(const LearnedSelections& fit, int count) {
  std::map<int, int> out;
  for (int k = 0; k < count; ++k) out[fit.numbers[k]] = fit.choice[k];
  return out;
}

TEST(LearningFromUse, TheTextbookP300IsReadThroughThePipelinesOwnFilters) {
  SignalInfo info;
  info.rate_hz = 256.0;
  info.block_size = 15;
  info.channels = {"Fz", "Pz", "Oz"};
  PipelineSettings pipeline;
  pipeline.decimate_hz = 20.0;
  const Eigen::VectorXd shape = p300Template(pipeline, info);
  const FeatureExtractor extractor(pipeline, info);
  ASSERT_EQ(shape.size(), extractor.shape().size());
  const int bins = extractor.shape().bins;
  // Only Pz carries it; there it peaks positive near 350 ms, and the causal high-pass leaves
  // something of the other sign after it.
  EXPECT_EQ(shape.head(bins).norm(), 0.0);
  EXPECT_EQ(shape.tail(bins).norm(), 0.0);
  const Eigen::VectorXd pz = shape.segment(bins, bins);
  Eigen::Index peak = 0;
  EXPECT_GT(pz.maxCoeff(&peak), 0.3);
  const double peak_s = pipeline.window.start_s + (peak + 0.5) * extractor.shape().bin_s;
  EXPECT_GT(peak_s, 0.3);
  EXPECT_LT(peak_s, 0.5);
  EXPECT_LT(pz.minCoeff(), 0.0);
  // No parietal or central site: nothing is known.
  info.channels = {"Fz", "Oz"};
  EXPECT_EQ(p300Template(pipeline, info).size(), 0);
}

TEST(LearningFromUse, TrustNeedsEnoughSelectionsAndAConsistentStableFit) {
  const TrustRule rule{5, 0.8};
  const LearnedSelections few = fitOf(3, 1.0);
  Trust trust = judgeTrust(few, decodings(few, 2), rule);
  EXPECT_FALSE(trust.trusted);
  EXPECT_EQ(trust.waiting_for, "2 more selections");

  const LearnedSelections weak = fitOf(10, 0.7);
  trust = judgeTrust(weak, decodings(weak, 9), rule);
  EXPECT_FALSE(trust.trusted);
  EXPECT_NE(trust.waiting_for.find("decode the same when left out of the fit: 7 of 10 do (0.70), "
                                   "0.80 needed"),
            std::string::npos)
      << trust.waiting_for;

  const LearnedSelections good = fitOf(12, 0.9);
  trust = judgeTrust(good, decodings(good, 11), rule);
  EXPECT_TRUE(trust.trusted) << trust.waiting_for;
  EXPECT_TRUE(trust.waiting_for.empty());

  LearnedSelections noise = fitOf(12, 0.9);
  noise.beats_shuffled = 8;
  noise.explained = 0.012;
  trust = judgeTrust(noise, decodings(noise, 11), rule);
  EXPECT_FALSE(trust.trusted);
  EXPECT_NE(trust.waiting_for.find("no better than with the flashes' order shuffled (beaten in 8 "
                                   "of 9 shuffles"),
            std::string::npos)
      << trust.waiting_for;

  LearnedSelections mirror = fitOf(12, 0.9);
  mirror.p3_uv = -0.8;
  trust = judgeTrust(mirror, decodings(mirror, 11), rule);
  EXPECT_FALSE(trust.trusted);
  EXPECT_NE(trust.waiting_for.find("a positive P300"), std::string::npos) << trust.waiting_for;

  // One of eleven earlier selections decoded otherwise is within a tenth; two are not: the fit
  // changed its mind, and the arm waits.
  std::map<int, int> before = decodings(good, 11);
  before[2] = (before[2] + 1) % 4;
  EXPECT_TRUE(judgeTrust(good, before, rule).trusted);
  before[4] = (before[4] + 1) % 4;
  trust = judgeTrust(good, before, rule);
  EXPECT_FALSE(trust.trusted);
  EXPECT_EQ(trust.changed, (std::vector<int>{2, 4}));
  EXPECT_NE(trust.waiting_for.find("changed: 2, 4"), std::string::npos) << trust.waiting_for;

  // Below ten selections compared, one may still change (a tenth of them is less than one).
  const LearnedSelections five = fitOf(5, 1.0);
  std::map<int, int> four = decodings(five, 4);
  four[6] = (four[6] + 1) % 4;
  EXPECT_TRUE(judgeTrust(five, four, rule).trusted) << judgeTrust(five, four, rule).waiting_for;
  four[2] = (four[2] + 1) % 4;
  EXPECT_FALSE(judgeTrust(five, four, rule).trusted);
}

}  // namespace
}  // namespace arbci::bci
