// The P300 stage on hand-built records with a simulated subject's EEG: the calibration run's
// cued flashes kept and trained on when asked (a retaken selection left out), the next selection
// scored and decided by the model trained, epochs that touch lost samples discarded, and a model
// that does not fit the channels refused with the reason; without a calibration run, the online
// selections learnt from without their labels, and a model learnt from a subject who attends
// nothing held to the separation the selections it had not seen show.
#include <gtest/gtest.h>

#include "arbci/bci/settings.h"
#include "arbci/session/stages/p300_stage.h"
#include "support/flash_driver.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

P300Settings settingsFor(const bci::SignalInfo& info) {
  P300Settings s;
  s.info = info;
  s.flash_s = 4.0 / 60.0;
  s.object_stimuli = 4;
  s.session_file = "test.json";
  return s;
}

class P300StageTest : public ::testing::Test {
 protected:
  P300StageTest()
      : bench_("p300"), eeg_(bench_, 4), stage_(settingsFor(eeg_.info()), bench_.services()) {}
  test::StageBench bench_;
  test::FlashDriver eeg_;
  P300Stage stage_;
};

TEST_F(P300StageTest, TheCalibrationIsTrainedOnWhenAskedAndTheModelDecidesTheNextSelection) {
  // Six cued selections, the third interrupted and retaken as the fourth.
  const int targets[] = {1, 3, 2, 2, 4, 1};
  for (int n = 1; n <= 6; ++n) {
    const int sequences = n == 3 ? 2 : 8;
    eeg_.selection(stage_, n, targets[n - 1], true, sequences,
                   n == 4 ? std::optional<int>(3) : std::nullopt);
  }
  EXPECT_EQ(bench_.previous.p300.model, nullptr);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);  // stepped: the training is waited for on this cycle
  const P300Part& trained = bench_.previous.p300;
  ASSERT_TRUE(trained.training_error.empty()) << trained.training_error;
  ASSERT_TRUE(trained.trained.has_value());
  ASSERT_NE(trained.model, nullptr);
  EXPECT_EQ(trained.model->method, "slda");
  EXPECT_EQ(trained.trained_on, (std::vector<int>{1, 2, 4, 5, 6}));
  EXPECT_EQ(trained.left_out, (std::vector<int>{3}));
  EXPECT_GT(trained.trained->auc, 0.75);
  ASSERT_NE(trained.erp, nullptr);
  // Online: nobody says which is attended; the model finds it.
  eeg_.selection(stage_, 7, 3, false, 8);
  const P300Part& online = bench_.previous.p300;
  EXPECT_EQ(online.selection, 7);
  EXPECT_EQ(online.presented, 32);
  EXPECT_EQ(online.scored, 32);
  EXPECT_EQ(online.sequences, 8);
  EXPECT_EQ(online.decision.codes, std::set<int>{3});
  EXPECT_GT(online.decision.certainty, 0.5);
}

TEST(P300StageLearning, WithoutACalibrationRunItLearnsFromTheSelectionsNotTheirLabels) {
  // Online selections only, each flash labelled with the wrong object: the stage fits after each
  // selection and its post-hoc decodings are what the subject attended, not what the labels say.
  test::StageBench bench("p300_learning");
  test::FlashDriver eeg(bench, 4);
  P300Settings settings = settingsFor(eeg.info());
  settings.learn = true;
  P300Stage stage(settings, bench.services());
  const int attended[] = {2, 4, 1, 3, 3, 1, 4, 2, 1, 2};
  for (int n = 1; n <= 10; ++n)
    eeg.selection(stage, n, attended[n - 1], false, 8, std::nullopt, 1.0, attended[n - 1] % 4 + 1);
  ASSERT_NE(bench.previous.p300.learning, nullptr);
  EXPECT_FALSE(bench.previous.p300.learning->adapting);
  EXPECT_NE(bench.previous.p300.model, nullptr);  // the fits' model decides meanwhile
  session::Cycle closing = bench.cycle();
  stage.stop(closing, "finished");  // the last fit, with the last selection in
  const auto& learning = bench.record.p300.learning;
  ASSERT_NE(learning, nullptr);
  EXPECT_TRUE(learning->error.empty()) << learning->error;
  EXPECT_GE(learning->fits, 8);
  ASSERT_EQ(learning->post_hoc.size(), 10u);
  int right = 0, as_labelled = 0;
  for (const auto& [number, code] : learning->post_hoc) {
    right += code == attended[number - 1];
    as_labelled += code == attended[number - 1] % 4 + 1;
  }
  EXPECT_GE(right, 9);
  EXPECT_LE(as_labelled, 1);
  const auto fits = bench.logged("learning_fit");
  EXPECT_EQ(fits.size(), static_cast<size_t>(learning->fits));
  // The selections decided by models that had not seen them show the response too.
  ASSERT_FALSE(fits.back()["separation_held_out"].is_null());
  EXPECT_GT(fits.back()["separation_held_out"].get<double>(), 0.5);
}

TEST(P300StageLearning, AModelLearntFromNoResponseClaimsNoMoreThanTheSelectionsDecidedShow) {
  // The subject attends none of the objects: any labels a fit finds are noise that fits itself,
  // and each fit's certainty is held to what the selections it had not seen show.
  test::StageBench bench("p300_learning_noise");
  test::FlashDriver eeg(bench, 4);
  eeg.lookAway();
  P300Settings settings = settingsFor(eeg.info());
  settings.learn = true;
  P300Stage stage(settings, bench.services());
  for (int n = 1; n <= 8; ++n) eeg.selection(stage, n, n % 4 + 1, false, 8);
  const P300Part& now = bench.previous.p300;
  ASSERT_NE(now.model, nullptr);
  ASSERT_NE(now.learning, nullptr);
  EXPECT_FALSE(now.learning->trusted);
  const auto fits = bench.logged("learning_fit");
  ASSERT_GE(fits.size(), 4u);
  // The model deciding now is the last fit taken.
  const nlohmann::json& last = fits.at(static_cast<size_t>(now.learning->fits) - 1);
  ASSERT_FALSE(last["separation_held_out"].is_null());
  const double fitted = last["separation_fitted"].get<double>();
  const double held_out = last["separation_held_out"].get<double>();
  const bci::ScoreModel& scores = now.model->score_model;
  EXPECT_NEAR(scores.separation(), std::min(fitted, std::max(held_out, 0.0)), 1e-9);
}

// The decision an offline analysis makes of the last `flashes` flashes shown: the whole signal
// through the model's filters at once (bci::buildDataset), scored and accumulated.
bci::Decision offlineDecision(const test::FlashDriver& eeg, const bci::P300Model& model,
                              int flashes) {
  bci::Recording r;
  r.info = eeg.info();
  for (const bci::Block& b : eeg.delivered()) r.samples += b.samples;
  r.data.assign(static_cast<size_t>(r.samples * r.info.channelCount()), 0.0f);
  std::int64_t at = 0;
  for (const bci::Block& b : eeg.delivered()) {
    for (int c = 0; c < b.channels; ++c) {
      for (int s = 0; s < b.samples; ++s)
        r.data[static_cast<size_t>(c * r.samples + at + s)] = b.at(c, s);
    }
    at += b.samples;
  }
  r.stimuli.assign(eeg.shown().end() - flashes, eeg.shown().end());
  r.parameters["Paradigm"] = "single stimulus, 4 stimuli";
  const bci::P300Dataset data = bci::buildDataset({r}, model.pipeline);
  bci::SelectionAccumulator accumulator(data.layout, model.score_model);
  for (int e = 0; e < data.epochs(); ++e)
    accumulator.add(data.code[static_cast<size_t>(e)],
                    model.classifier->score(data.features.row(e)));
  return accumulator.decide();
}

void expectSameEvidence(const bci::Decision& online, const bci::Decision& offline, double within) {
  ASSERT_EQ(online.flashes, offline.flashes);
  for (const auto& [code, evidence] : offline.evidence)
    EXPECT_NEAR(online.evidence.at(code), evidence, within) << "code " << code;
}

// A DC-coupled amplifier's offset (1 mV, 50 mV) and a slow drift: the model arrives between the
// calibration run and the first online selection, and that selection is scored exactly as an
// offline analysis of the whole signal scores it (the filter goes on; it never starts again in
// the middle of the signal).
TEST(P300StageFilter, TheFirstOnlineSelectionIsScoredAsOfflineDespiteAnOffsetAndDrift) {
  for (const double offset_uv : {1000.0, 50000.0}) {
    test::StageBench bench("p300_offset");
    test::FlashDriver eeg(bench, 4);
    eeg.amplifierOffset(offset_uv, 5.0);
    P300Stage stage(settingsFor(eeg.info()), bench.services());
    const int targets[] = {1, 3, 2, 4, 4, 2};
    for (int n = 1; n <= 6; ++n) eeg.selection(stage, n, targets[n - 1], true, 8);
    bench.record.requests.push_back(TrainRequest{"slda"});
    eeg.step(stage);
    ASSERT_NE(bench.previous.p300.model, nullptr) << bench.previous.p300.training_error;
    eeg.selection(stage, 7, 2, false, 8, std::nullopt, 0.0);  // at once, as trial 1 starts
    eeg.idle(stage, 1.0);
    const P300Part& online = bench.previous.p300;
    ASSERT_EQ(online.scored, 32);
    SCOPED_TRACE(offset_uv);
    expectSameEvidence(online.decision, offlineDecision(eeg, *online.model, 32), 1e-4);
    EXPECT_EQ(online.decision.codes, std::set<int>{2});
  }
}

// A model given with another filter mid-run: the new filter starts on the signal kept, so the
// next selection is scored as an offline analysis through that filter scores it, to within the
// new filter's memory of what came before the history.
TEST(P300StageFilter, AModelWithAnotherFilterStartsItOnTheSignalAlreadyReceived) {
  test::StageBench bench("p300_refilter");
  test::FlashDriver eeg(bench, 4);
  eeg.amplifierOffset(1000.0, 5.0);
  P300Stage stage(settingsFor(eeg.info()), bench.services());
  for (int n = 1; n <= 4; ++n) eeg.selection(stage, n, n, true, 6);
  bench.record.requests.push_back(TrainRequest{"slda"});
  eeg.step(stage);
  ASSERT_NE(bench.previous.p300.model, nullptr) << bench.previous.p300.training_error;
  bci::P300Model other = *bench.previous.p300.model;
  other.pipeline.filter.highpass_hz = 1.0;
  bench.record.requests.push_back(UseModelRequest{std::make_shared<const bci::P300Model>(other)});
  eeg.step(stage);
  eeg.selection(stage, 5, 3, false, 8, std::nullopt, 0.0);
  eeg.idle(stage, 1.0);
  const P300Part& online = bench.previous.p300;
  ASSERT_EQ(online.scored, 32);
  expectSameEvidence(online.decision, offlineDecision(eeg, other, 32), 0.05);
}

TEST_F(P300StageTest, RecalibrateAtTheReviewTrainsOnTheNewRunAlone) {
  for (int n = 1; n <= 3; ++n) eeg_.selection(stage_, n, n, true, 6);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  ASSERT_NE(bench_.previous.p300.model, nullptr) << bench_.previous.p300.training_error;
  // The review asked; the experimenter recalibrates: no model until the new run is trained.
  bench_.previous.paradigm.review = ParadigmPart::Review{};
  bench_.record.requests.push_back(RecalibrateRequest{});
  eeg_.step(stage_);
  EXPECT_EQ(bench_.previous.p300.model, nullptr);
  for (int n = 4; n <= 7; ++n) eeg_.selection(stage_, n, n - 3, true, 6);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  const P300Part& trained = bench_.previous.p300;
  ASSERT_NE(trained.model, nullptr) << trained.training_error;
  EXPECT_EQ(trained.trained_on, (std::vector<int>{4, 5, 6, 7}));
  EXPECT_GT(trained.trained->auc, 0.75);
  // Online, the new model decides.
  eeg_.selection(stage_, 8, 2, false, 8);
  EXPECT_EQ(bench_.previous.p300.decision.codes, std::set<int>{2});
}

TEST_F(P300StageTest, EpochsTouchingLostSamplesAreDiscardedNotScored) {
  for (int n = 1; n <= 3; ++n) eeg_.selection(stage_, n, n, true, 6);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  ASSERT_NE(bench_.previous.p300.model, nullptr) << bench_.previous.p300.training_error;
  // A second lost a little after the online selection starts.
  const std::int64_t now = static_cast<std::int64_t>(bench_.record.frame / 60.0 * 256.0);
  bench_.record.eeg.losses.push_back({now + 128, 256, "gap in the stream"});
  eeg_.selection(stage_, 4, 2, false, 4);
  EXPECT_EQ(bench_.previous.p300.scored, 16);
  EXPECT_FALSE(bench_.logged("epoch_discarded").empty());
  nlohmann::json summary;
  stage_.report(summary);
  EXPECT_EQ(summary["eeg"]["discarded_epochs"].get<int>(),
            static_cast<int>(bench_.logged("epoch_discarded").size()));
}

TEST_F(P300StageTest, AModelThatLacksTheSourcesChannelsIsRefusedWithTheReason) {
  for (int n = 1; n <= 3; ++n) eeg_.selection(stage_, n, n, true, 6);
  bench_.record.requests.push_back(TrainRequest{"slda"});
  eeg_.step(stage_);
  ASSERT_NE(bench_.previous.p300.model, nullptr);
  ASSERT_NE(bench_.previous.p300.erp, nullptr);
  // A model given in its place (here the same one) was not trained on this session's averages.
  bench_.record.requests.push_back(UseModelRequest{bench_.previous.p300.model});
  eeg_.step(stage_);
  EXPECT_EQ(bench_.previous.p300.erp, nullptr);
  const std::vector<std::string> kept = bench_.previous.p300.model->pipeline.channels;
  bci::P300Model other = *bench_.previous.p300.model;
  other.pipeline.channels = {"Fz", "Cz", "T7"};
  bench_.record.requests.push_back(UseModelRequest{std::make_shared<const bci::P300Model>(other)});
  eeg_.step(stage_);
  EXPECT_NE(bench_.previous.p300.training_error.find("T7"), std::string::npos)
      << bench_.previous.p300.training_error;
  EXPECT_TRUE(bench_.toldOf("model refused"));
  EXPECT_EQ(bench_.logged("model_refused").size(), 1u);
  // The session keeps the model it had.
  EXPECT_EQ(bench_.previous.p300.model->pipeline.channels, kept);
}

}  // namespace
}  // namespace arbci::session
