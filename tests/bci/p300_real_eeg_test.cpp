// P300 classification on real EEG (BCI2000's sample data): trained on eeg3_1 (T3OF), every
// method spells eeg3_2's 6MK? with 15 sequences; dynamic stopping keeps the accuracy with fewer
// flashes; the synthetic speller file spells SPELL.
#include <gtest/gtest.h>

#include <map>

#include "arbci/bci/p300_model.h"
#include "support/shared_data.h"

namespace arbci::bci {
namespace {

Recording sample(const std::string& name) {
  return readRecording(test::sharedData("eeg/bci2000_samplefiles/" + name));
}

struct Evaluated {
  TrainingResult trained;
  EvaluationReport test;
};

// Cached: each method is trained once for all tests.
const Evaluated& trainedOnEeg3_1(const std::string& method) {
  static std::map<std::string, Evaluated> cache;
  auto found = cache.find(method);
  if (found != cache.end()) return found->second;
  const PipelineSettings pipeline;
  TrainingSettings settings;
  settings.method = method;
  Evaluated e;
  e.trained = trainModel(buildDataset({sample("eeg3_1.dat")}, pipeline), pipeline, settings);
  const P300Dataset test = buildDataset({sample("eeg3_2.dat")}, e.trained.model.pipeline);
  std::vector<double> scores;
  for (int i = 0; i < test.epochs(); ++i)
    scores.push_back(e.trained.model.classifier->score(test.features.row(i).transpose()));
  e.test = evaluateScores(test, scores, e.trained.model.score_model, StoppingRule{15, 2, 0.99});
  return cache.emplace(method, std::move(e)).first->second;
}

class EachMethod : public ::testing::TestWithParam<std::string> {};

TEST_P(EachMethod, TrainedOnEeg3_1Spells6MKQuestionMarkOnEeg3_2) {
  const Evaluated& e = trainedOnEeg3_1(GetParam());
  ASSERT_EQ(e.test.max_sequences, 15);
  EXPECT_EQ(e.test.selected(15), "6MK?");
  EXPECT_DOUBLE_EQ(e.test.accuracy[14], 1.0);
  EXPECT_GE(e.test.auc, 0.90) << GetParam();
  // The training file itself, cross-validated by selection, spells T3OF.
  EXPECT_EQ(e.trained.cross_validation.report.selected(15), "T3OF");
}

TEST_P(EachMethod, DynamicStoppingKeepsTheAccuracyWithFewerFlashes) {
  const Evaluated& e = trainedOnEeg3_1(GetParam());
  EXPECT_DOUBLE_EQ(e.test.dynamic_accuracy, e.test.accuracy[14]);
  EXPECT_LT(e.test.dynamic_mean_flashes, 0.6 * 180.0);
  EXPECT_GT(e.test.dynamic_bits_per_minute, e.test.bits_per_minute[14]);
  EXPECT_EQ(e.test.selectedDynamic(), "6MK?");
}

INSTANTIATE_TEST_SUITE_P(Methods, EachMethod, ::testing::Values("swlda", "slda", "xdawn"));

TEST(P300RealEeg, SwldaKeepsAtMost60FeaturesAndExportsToBci2000) {
  const Evaluated& e = trainedOnEeg3_1("swlda");
  const P300Model& model = e.trained.model;
  const Eigen::VectorXd w = model.classifier->weights();
  const int kept = static_cast<int>((w.array() != 0.0).count());
  EXPECT_GT(kept, 0);
  EXPECT_LE(kept, 60);
  // The fragment's per-sample weights applied to a full-rate epoch give the model's score.
  const std::string fragment = model.bci2000Fragment();
  std::istringstream in(fragment.substr(fragment.find('}') + 1));
  const Recording r = sample("eeg3_2.dat");
  const P300Dataset data = buildDataset({r}, model.pipeline);
  Block signal(0, 8, static_cast<int>(r.samples));
  signal.data = r.data;
  FilterChain(model.pipeline.filter, r.info).process(signal);
  const std::int64_t onset = r.stimuli[10].sample;
  double bci2000_score = 0.0;
  int entries = 0, channel = 0, element = 0, output = 0;
  double weight = 0.0;
  while (in >> channel >> element >> output >> weight) {
    bci2000_score += weight * signal.at(channel - 1, static_cast<int>(onset) + element - 1);
    ++entries;
  }
  EXPECT_EQ(entries, kept * 13);
  EXPECT_NEAR(bci2000_score + model.classifier->bias(),
              model.classifier->score(data.features.row(10).transpose()), 1e-3);
  EXPECT_NE(fragment.find("EpochLength= 800ms"), std::string::npos);
}

TEST(P300RealEeg, SyntheticSpellerFileSpellsSPELL) {
  const PipelineSettings pipeline;
  const P300Dataset data = buildDataset({sample("P3SpellerS001R01_synthetic.dat")}, pipeline);
  ASSERT_EQ(data.selections.size(), 5u);
  TrainingSettings settings;
  const CrossValidation cv = crossValidate(data, settings);
  EXPECT_EQ(cv.report.selected(2), "SPELL");
}

}  // namespace
}  // namespace arbci::bci
