// The ErrP stage on hand-built records with a simulated subject's EEG: the calibration run's
// feedback block (cued, a quarter deliberately wrong) kept and trained on when asked, its averages
// those of the error and correct feedbacks (an error's negativity, then its positivity, at Cz); a
// later feedback scored once its epoch is complete, errors above correct ones; a model given in
// its place drops the averages; a stage without ErrPs keeps and trains nothing.
#include <gtest/gtest.h>

#include "arbci/session/session_config.h"
#include "arbci/session/stages/errp_stage.h"
#include "support/flash_driver.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

ErrpStageSettings settingsFor(const bci::SignalInfo& info, bool enabled = true) {
  const ErrpSettings errp;
  ErrpStageSettings s;
  s.enabled = enabled;
  s.info = info;
  s.pipeline = errp.pipeline(bci::PipelineSettings{}, info.channels);
  s.training = errp.training();
  s.flash_s = 4.0 / 60.0;
  return s;
}

class ErrpStageTest : public ::testing::Test {
 protected:
  explicit ErrpStageTest(bool enabled = true)
      : bench_("errp"),
        eeg_(bench_, 4),
        stage_(settingsFor(eeg_.info(), enabled), bench_.services()) {}
  // The calibration's feedback block: `n` cued feedbacks a second apart, every fourth wrong.
  void feedbackBlock(int n) {
    eeg_.idle(stage_, 1.0);  // an epoch needs the signal before its feedback
    for (int k = 0; k < n; ++k) {
      const int target = 1 + k % 4;
      const bool wrong = k % 4 == 3;
      SelectionStart cued;
      cued.selection = k + 1;
      cued.target = target;
      bench_.previous.paradigm.selection_started = cued;
      eeg_.subject().attend({target});
      eeg_.feedback({wrong ? 1 + (target % 4) : target}, wrong);
      eeg_.idle(stage_, 1.0);
    }
  }
  // An online feedback (nobody cued it); its score once its epoch is complete.
  std::optional<double> onlineFeedback(bool wrong) {
    SelectionStart online;
    online.selection = 1000;
    bench_.previous.paradigm.selection_started = online;
    eeg_.subject().attend({2});
    eeg_.feedback({wrong ? 3 : 2}, std::nullopt);
    std::optional<double> score;
    for (int i = 0; i < 60 && !score; ++i) {
      eeg_.step(stage_);
      if (bench_.previous.errp.score) score = bench_.previous.errp.score->second;
    }
    eeg_.idle(stage_, 0.3);
    return score;
  }
  test::StageBench bench_;
  test::FlashDriver eeg_;
  ErrpStage stage_;
};

TEST_F(ErrpStageTest, TheFeedbackBlockIsTrainedOnAndLaterFeedbackIsScored) {
  feedbackBlock(80);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  const ErrpPart& trained = bench_.previous.errp;
  ASSERT_TRUE(trained.training_error.empty()) << trained.training_error;
  ASSERT_TRUE(trained.trained.has_value());
  ASSERT_NE(trained.model, nullptr);
  EXPECT_TRUE(trained.enabled);
  EXPECT_NEAR(trained.auc, trained.trained->auc, 1e-12);
  ASSERT_NE(trained.erp, nullptr);
  const bci::ErpCurves& erp = *trained.erp;
  EXPECT_EQ(erp.targets, 20);
  EXPECT_EQ(erp.others, 60);
  // The simulated ErrP at Cz: a negativity, then a later positivity (extremes: a fixed window's
  // mean over 20 errors is as much noise as response).
  const auto cz = std::find(erp.channels.begin(), erp.channels.end(), "Cz");
  ASSERT_NE(cz, erp.channels.end());
  const std::vector<double> difference =
      bci::ErpCurves::row(erp.difference(), static_cast<int>(cz - erp.channels.begin()));
  int trough = -1, peak = -1;
  for (int i = 0; i < erp.samples(); ++i) {
    const double t = erp.timeS(i);
    if (t >= 0.15 && t < 0.35 && (trough < 0 || difference[i] < difference[trough])) trough = i;
    if (t >= 0.25 && t < 0.55 && (peak < 0 || difference[i] > difference[peak])) peak = i;
  }
  ASSERT_GE(trough, 0);
  ASSERT_GE(peak, 0);
  EXPECT_LT(difference[trough], -1.0);
  EXPECT_GT(difference[peak], 1.0);
  EXPECT_GT(erp.timeS(peak), erp.timeS(trough));
  // Online: errors score above correct feedback on average.
  double errors = 0, corrects = 0;
  for (int k = 0; k < 6; ++k) {
    const auto error = onlineFeedback(true);
    const auto correct = onlineFeedback(false);
    ASSERT_TRUE(error && correct);
    errors += *error;
    corrects += *correct;
  }
  EXPECT_GT(errors, corrects);
  // A model given in its place (here without an ErrP classifier) was not trained on these.
  bench_.record.requests.push_back(UseModelRequest{std::make_shared<const bci::P300Model>()});
  eeg_.step(stage_);
  EXPECT_EQ(bench_.previous.errp.model, nullptr);
  EXPECT_EQ(bench_.previous.errp.erp, nullptr);
}

TEST_F(ErrpStageTest, TooFewFeedbacksToTrainAreAFailedTrainingWithTheReason) {
  feedbackBlock(8);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  EXPECT_FALSE(bench_.previous.errp.training_error.empty());
  EXPECT_EQ(bench_.previous.errp.model, nullptr);
}

class DisabledErrpStageTest : public ErrpStageTest {
 protected:
  DisabledErrpStageTest() : ErrpStageTest(false) {}
};

TEST_F(DisabledErrpStageTest, WithoutErrpsNothingIsKeptOrTrained) {
  feedbackBlock(8);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  EXPECT_FALSE(bench_.previous.errp.enabled);
  EXPECT_FALSE(bench_.previous.errp.training);
  EXPECT_FALSE(bench_.previous.errp.trained.has_value());
  EXPECT_TRUE(bench_.previous.errp.training_error.empty());
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_FALSE(summary.contains("errp"));
}

}  // namespace
}  // namespace arbci::session
