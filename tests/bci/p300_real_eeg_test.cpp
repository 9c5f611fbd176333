// P300 classification on real EEG (BCI2000's sample data): trained on eeg3_1 (T3OF), every
// method spells eeg3_2's 6MK? with 15 sequences; dynamic stopping keeps the accuracy with fewer
// flashes; the synthetic speller file spells SPELL.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "arbci/bci/learning_from_use.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/unsupervised.h"
#include "support/shared_data.h"
#include "support/test_files.h"
#include "support/xdf_writer.h"

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
  TrainingSettings settings;
  settings.method = method;
  const PipelineSettings pipeline = withMethodRate(PipelineSettings{}, method);
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
  const PipelineSettings pipeline = withMethodRate(PipelineSettings{}, TrainingSettings{}.method);
  const P300Dataset data = buildDataset({sample("P3SpellerS001R01_synthetic.dat")}, pipeline);
  ASSERT_EQ(data.selections.size(), 5u);
  TrainingSettings settings;
  const CrossValidation cv = crossValidate(data, settings);
  EXPECT_EQ(cv.report.selected(2), "SPELL");
}

// eeg3_1 through XDF as LabRecorder would record it from ARBCI's outlets (`arbci eeg stream`):
// the EEG, its flashes as markers, the layout in the marker stream's description. It trains as
// the original does; without the layout, it would be read as 12 single stimuli.
TEST(P300RealEeg, Eeg3_1ThroughXdfWithItsLayoutTrainsAsTheOriginal) {
  const Recording original = sample("eeg3_1.dat");
  test::XdfNumericStream eeg;
  eeg.name = "eeg3_1";
  eeg.rate = original.info.rate_hz;
  eeg.labels = original.info.channels;
  for (std::int64_t s = 0; s < original.samples; ++s) {
    std::vector<float> values;
    for (int c = 0; c < original.info.channelCount(); ++c) values.push_back(original.at(c, s));
    eeg.samples.push_back(std::move(values));
  }
  std::vector<test::XdfMarker> markers;
  for (const StimulusEvent& e : original.stimuli)
    markers.push_back({eeg.first_timestamp + static_cast<double>(e.sample) / eeg.rate,
                       "flash " + std::to_string(e.code) + (e.target ? " target" : " nontarget"),
                       {}});
  test::XdfExtras extras;
  extras.marker_parameters = layoutParameters(original);
  const auto path = test::freshTempPath("p300_xdf", "eeg3_1.xdf");
  test::writeXdf(path, eeg, markers, extras);
  const Recording through = readRecording(path);
  ASSERT_EQ(through.samples, original.samples);
  ASSERT_EQ(through.stimuli.size(), original.stimuli.size());
  const ParadigmLayout layout = layoutOf(through);
  EXPECT_EQ(layout.describeShape(), layoutOf(original).describeShape());

  TrainingSettings settings;
  const PipelineSettings pipeline = withMethodRate(PipelineSettings{}, settings.method);
  const TrainingResult from_xdf = trainModel(buildDataset({through}, pipeline), pipeline, settings);
  const TrainingResult from_dat =
      trainModel(buildDataset({original}, pipeline), pipeline, settings);
  EXPECT_EQ(from_xdf.cross_validation.report.selected(15), "T3OF");
  EXPECT_EQ(from_xdf.cross_validation.report.accuracy, from_dat.cross_validation.report.accuracy);

  // Without the layout the same file is 12 single stimuli.
  const auto bare = test::freshTempPath("p300_xdf", "eeg3_1_bare.xdf");
  test::writeXdf(bare, eeg, markers);
  EXPECT_EQ(layoutOf(readRecording(bare)).kind, ParadigmLayout::Kind::SingleStimulus);
}

}  // namespace
}  // namespace arbci::bci

namespace arbci::bci {
namespace {

// Without labels: both copy-spelling runs with every flash's label erased ("U", as a free choice
// online is recorded) are still learnt from, and the attended cells found spell what the subject
// copied.
TEST(P300RealEegUnsupervised, RecordingsWithoutLabelsSpellWhatWasCopied) {
  std::vector<Recording> recordings = {sample("eeg3_1.dat"), sample("eeg3_2.dat")};
  for (Recording& r : recordings) {
    for (StimulusEvent& e : r.stimuli) {
      e.known = false;
      e.target = false;
    }
  }
  DatasetOptions options;
  options.keep_unknown = true;
  const PipelineSettings pipeline = withMethodRate(PipelineSettings{}, "slda");
  const P300Dataset data = buildDataset(recordings, pipeline, {}, options);
  ASSERT_EQ(data.selections.size(), 8u);
  EXPECT_EQ(std::count(data.target.begin(), data.target.end(), true), 0);
  const UnsupervisedReport report = evaluateWithoutLabels(data);
  EXPECT_FALSE(report.labelled);
  std::string spelled;
  for (int choice : report.fit.choice)
    spelled += data.layout.symbols.at(static_cast<size_t>(choice));
  EXPECT_EQ(spelled, "T3OF6MK?");
  EXPECT_GE(report.fit.agreeing, 2);
  // What an online session would trust it by: a response beyond every fit of the shuffled codes,
  // found again without each selection.
  EXPECT_EQ(report.fit.beats_shuffled, 9);
  EXPECT_GE(report.fit.consistency, 0.8);
  // As a session learns from it: its P300 is positive along the textbook one put through the
  // online (causal) filters. (Averaged over a fixed parietal window from 250 to 500 ms, its
  // features' target minus non-target is negative, the filters' high-pass rebound: a sign read
  // there took the right fit for the mirror.)
  const Recording& second = recordings[1];
  std::vector<int> numbers;
  std::int64_t previous = -1;
  int number = 0;
  for (const StimulusEvent& e : second.stimuli) {
    if (previous < 0 || e.sample - previous > second.info.rate_hz) ++number;
    previous = e.sample;
    numbers.push_back(number);
  }
  const LearnedSelections learnt =
      learnFromUse(second, numbers, {}, {}, pipeline, TrainingSettings{});
  ASSERT_TRUE(learnt.p3_uv.has_value());
  EXPECT_GT(*learnt.p3_uv, 0.0);
}

}  // namespace
}  // namespace arbci::bci
