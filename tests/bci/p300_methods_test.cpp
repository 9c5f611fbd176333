// The parts of P300 classification on data whose answer is known: SWLDA's feature selection,
// the metrics, decisions and their certainty, cross-validation without leakage, models that
// survive a round trip and refuse the wrong signal, and the simulated subject's difficulty.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "../../bci/src/statistics.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/bci/stimulus_sequence.h"

namespace arbci::bci {
namespace {

TEST(Statistics, StudentTPValuesMatchTables) {
  EXPECT_NEAR(studentTwoSidedP(2.228, 10), 0.05, 1e-3);
  EXPECT_NEAR(studentTwoSidedP(1.96, 1e6), 0.05, 1e-3);
  EXPECT_NEAR(studentTwoSidedP(0.0, 5), 1.0, 1e-12);
  EXPECT_NEAR(studentTwoSidedP(-2.571, 5), 0.05, 1e-3);
  EXPECT_NEAR(incompleteBeta(2.0, 3.0, 0.4), 0.5248, 1e-4);
}

TEST(Metrics, AucAndWolpawBits) {
  EXPECT_DOUBLE_EQ(areaUnderCurve({1, 2, 3, 4}, {false, false, true, true}), 1.0);
  EXPECT_DOUBLE_EQ(areaUnderCurve({1, 2, 3, 4}, {true, true, false, false}), 0.0);
  EXPECT_DOUBLE_EQ(areaUnderCurve({1, 1, 1, 1}, {true, false, true, false}), 0.5);
  EXPECT_DOUBLE_EQ(areaUnderCurve({1, 3, 2, 4}, {false, true, false, true}), 1.0);
  EXPECT_NEAR(wolpawBits(36, 1.0), std::log2(36.0), 1e-12);
  EXPECT_DOUBLE_EQ(wolpawBits(4, 0.25), 0.0);
  EXPECT_NEAR(wolpawBits(2, 0.9), 1.0 + 0.9 * std::log2(0.9) + 0.1 * std::log2(0.1), 1e-12);
}

// Noise features with a target effect on features 3, 17 and 40 only.
void plantedData(Eigen::MatrixXd& x, std::vector<bool>& target, int n = 600, int p = 50) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  x.resize(n, p);
  target.clear();
  for (int i = 0; i < n; ++i) {
    target.push_back(i % 6 == 0);
    for (int j = 0; j < p; ++j) x(i, j) = normal(random);
    if (target.back()) {
      x(i, 3) += 1.0;
      x(i, 17) -= 0.8;
      x(i, 40) += 0.6;
    }
  }
}

TEST(Swlda, SelectsThePlantedFeaturesAndRespectsItsLimit) {
  Eigen::MatrixXd x;
  std::vector<bool> target;
  plantedData(x, target);
  TrainingSettings settings;
  settings.method = "swlda";
  settings.swlda.p_enter = 0.001;
  settings.swlda.p_remove = 0.01;
  auto swlda = makeClassifier(settings);
  swlda->train(x, target, FeatureShape{5, 10});
  const Eigen::VectorXd w = swlda->weights();
  std::vector<int> kept;
  for (int j = 0; j < w.size(); ++j) {
    if (w[j] != 0.0) kept.push_back(j);
  }
  EXPECT_EQ(kept, (std::vector<int>{3, 17, 40}));
  EXPECT_GT(w[3], 0.0);
  EXPECT_LT(w[17], 0.0);
  settings.swlda.max_features = 2;
  auto limited = makeClassifier(settings);
  limited->train(x, target, FeatureShape{5, 10});
  EXPECT_EQ((limited->weights().array() != 0.0).count(), 2);
}

TEST(Classifiers, TooFewTargetsAndUnknownMethodsAreRefused) {
  Eigen::MatrixXd x;
  std::vector<bool> target;
  plantedData(x, target, 40);
  for (const std::string method : {"swlda", "slda", "xdawn"}) {
    TrainingSettings settings;
    settings.method = method;
    try {
      makeClassifier(settings)->train(x, target, FeatureShape{5, 10});
      ADD_FAILURE() << method;
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("too few"), std::string::npos) << error.what();
    }
  }
  TrainingSettings unknown;
  unknown.method = "svm";
  EXPECT_THROW(makeClassifier(unknown), std::invalid_argument);
}

// Plain LDA, the unregularised baseline: on well-conditioned data (many epochs, few features) it
// is shrinkage LDA without the shrinkage, the same direction; it is in the registry, and a model
// with it survives its JSON.
TEST(Classifiers, PlainLdaIsShrinkageLdaWithoutTheShrinkage) {
  Eigen::MatrixXd x;
  std::vector<bool> target;
  plantedData(x, target, 2000);
  TrainingSettings settings;
  settings.method = "lda";
  auto lda = makeClassifier(settings);
  lda->train(x, target, FeatureShape{5, 10});
  settings.method = "slda";
  auto slda = makeClassifier(settings);
  slda->train(x, target, FeatureShape{5, 10});
  const Eigen::VectorXd a = lda->weights().normalized(), b = slda->weights().normalized();
  EXPECT_GT(a.dot(b), 0.99);
  const auto restored = classifierFromJson(lda->toJson(), FeatureShape{5, 10});
  EXPECT_EQ(restored->method(), "lda");
  EXPECT_DOUBLE_EQ(restored->score(x.row(3).transpose()), lda->score(x.row(3).transpose()));
  EXPECT_NE(classifiers().list().find("lda"), std::string::npos);
}

// Epochs of 4 channels x 24 bins of 50 ms whose target response (a bump on channels 0 and 1)
// comes up to 3 bins early or late.
void jitteredData(Eigen::MatrixXd& x, std::vector<bool>& target, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> jitter(-3, 3);
  const int n = 800, channels = 4, bins = 24;
  x.resize(n, channels * bins);
  target.clear();
  for (int i = 0; i < n; ++i) {
    target.push_back(i % 4 == 0);
    for (int j = 0; j < x.cols(); ++j) x(i, j) = normal(random);
    if (!target.back()) continue;
    const int peak = 12 + jitter(random);
    for (int b = 0; b < bins; ++b) {
      const double bump = 1.2 * std::exp(-0.5 * (b - peak) * (b - peak) / 1.5);
      x(i, 0 * bins + b) += bump;
      x(i, 1 * bins + b) += 0.7 * bump;
    }
  }
}

// Where the response's latency varies, the shifted template separates better than a fixed one,
// and a restored model scores as the trained one.
TEST(Classifiers, ShiftLdaToleratesLatencyJitterAndRoundTrips) {
  Eigen::MatrixXd train_x, test_x;
  std::vector<bool> train_y, test_y;
  jitteredData(train_x, train_y, 3);
  jitteredData(test_x, test_y, 4);
  const FeatureShape shape{4, 24, 0.05};
  const auto auc = [&](const Classifier& c) {
    std::vector<double> scores;
    for (Eigen::Index i = 0; i < test_x.rows(); ++i)
      scores.push_back(c.score(test_x.row(i).transpose()));
    return areaUnderCurve(scores, test_y);
  };
  TrainingSettings settings;
  settings.method = "slda";
  const auto fixed = makeClassifier(settings);
  fixed->train(train_x, train_y, shape);
  settings.method = "shift-lda";
  settings.shift_ms = 150.0;  // 3 bins each way
  settings.xdawn.filters = 1;
  const auto shifted = makeClassifier(settings);
  shifted->train(train_x, train_y, shape);
  EXPECT_GT(auc(*shifted), auc(*fixed) + 0.03) << auc(*shifted) << " vs " << auc(*fixed);
  EXPECT_EQ(shifted->weights().size(), 0);  // not linear: no BCI2000 export
  const auto restored = classifierFromJson(shifted->toJson(), shape);
  for (Eigen::Index i = 0; i < 20; ++i)
    EXPECT_DOUBLE_EQ(restored->score(test_x.row(i).transpose()),
                     shifted->score(test_x.row(i).transpose()));
  // A window too short for its shifts, and features of unknown bin length, are refused.
  settings.shift_ms = 600.0;
  EXPECT_THROW(makeClassifier(settings)->train(train_x, train_y, shape), std::invalid_argument);
  settings.shift_ms = 150.0;
  EXPECT_THROW(makeClassifier(settings)->train(train_x, train_y, FeatureShape{4, 24}),
               std::invalid_argument);
}

TEST(Decisions, RowAndColumnWithCertaintyGrowingOverSequences) {
  const ParadigmLayout layout = ParadigmLayout::matrix(6, 6);
  const ScoreModel model{1.0, -0.2, 1.0};
  SelectionAccumulator accumulator(layout, model);
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  double after_one = 0.0;
  for (int sequence = 0; sequence < 8; ++sequence) {
    for (int code = 1; code <= 12; ++code) {
      const bool target = code == 2 || code == 11;  // row 2, column 5
      accumulator.add(code, (target ? 1.0 : -0.2) + noise(random));
    }
    if (sequence == 0) after_one = accumulator.decide().certainty;
  }
  const Decision d = accumulator.decide();
  EXPECT_EQ(d.codes, (std::set<int>{2, 11}));
  EXPECT_EQ(d.choice, 1 * 6 + 4);
  EXPECT_GT(d.certainty, 0.9);
  EXPECT_GT(d.certainty, after_one);
  EXPECT_EQ(accumulator.completeSequences(), 8);
  EXPECT_TRUE(accumulator.shouldStop(StoppingRule{15, 2, 0.9}));
  EXPECT_FALSE(accumulator.shouldStop(StoppingRule{15, 2, 0.0}));
}

// Features identical for every flash of a code within a selection, random between selections:
// a split by flash would learn each selection by heart; a split by selection cannot.
TEST(CrossValidation, SplitsBySelectionSoNothingLeaks) {
  P300Dataset data;
  data.layout = ParadigmLayout::single(4);
  data.shape = {2, 5};
  data.info.channels = {"Cz", "Pz"};
  std::mt19937 random(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::VectorXd> rows;
  for (int s = 0; s < 12; ++s) {
    SelectionEpochs selection;
    const int attended = 1 + s % 4;
    selection.target_codes = {attended};
    std::vector<Eigen::VectorXd> per_code(5);
    for (int code = 1; code <= 4; ++code) {
      per_code[code] = Eigen::VectorXd(10);
      for (int j = 0; j < 10; ++j) per_code[code][j] = normal(random);
    }
    for (int sequence = 0; sequence < 10; ++sequence) {
      for (int code = 1; code <= 4; ++code) {
        rows.push_back(per_code[code]);
        data.target.push_back(code == attended);
        data.code.push_back(code);
        data.sequence.push_back(sequence);
        data.selection.push_back(s);
        selection.epochs.push_back(static_cast<int>(rows.size()) - 1);
      }
    }
    data.selections.push_back(selection);
  }
  data.features.resize(static_cast<Eigen::Index>(rows.size()), 10);
  for (size_t i = 0; i < rows.size(); ++i)
    data.features.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  TrainingSettings settings;
  settings.method = "slda";
  settings.folds = 4;
  const CrossValidation cv = crossValidate(data, settings);
  EXPECT_EQ(cv.folds, 4);
  EXPECT_LT(cv.report.auc, 0.7);  // chance, not the 1.0 a leaking split gives
  EXPECT_LT(cv.report.accuracy.back(), 0.6);
}

// A copy-task recording of the simulated subject, in memory.
Recording simulatedCopyTask(std::uint64_t seed, int selections) {
  SimulatedSubjectConfig config;
  config.seed = seed;
  SimulatedSubject subject(config, std::make_shared<UnboundedClock>());
  Recording r;
  r.source = "simulated";
  r.info = subject.info();
  r.parameters["Paradigm"] = "single stimulus, 4 stimuli";
  StimulusSequencer sequencer(4, seed);
  std::mt19937 random(static_cast<unsigned>(seed));
  std::vector<std::vector<float>> channels(8);
  std::int64_t next = 256;
  for (int s = 0; s < selections; ++s) {
    const int attended = 1 + static_cast<int>(random() % 4);
    subject.attend({attended});
    std::vector<StimulusEvent> flashes;
    for (int sequence = 0; sequence < 10; ++sequence) {
      for (int code : sequencer.next()) {
        flashes.push_back({next, code, code == attended, 15});
        next += 46;
      }
    }
    next += 512;
    size_t presented = 0;
    while (subject.samplesGenerated() < next) {
      while (presented < flashes.size() &&
             flashes[presented].sample < subject.samplesGenerated() + 15)
        subject.present(flashes[presented++]);
      for (const Block& b : subject.poll(1)) {
        for (int c = 0; c < 8; ++c) {
          for (int i = 0; i < b.samples; ++i) channels[c].push_back(b.at(c, i));
        }
      }
    }
    r.stimuli.insert(r.stimuli.end(), flashes.begin(), flashes.end());
  }
  r.samples = static_cast<std::int64_t>(channels[0].size());
  for (const auto& c : channels) r.data.insert(r.data.end(), c.begin(), c.end());
  return r;
}

TEST(SimulatedSubject, SingleFlashesAreHardAndRepetitionsHelp) {
  TrainingSettings settings;
  settings.method = "slda";
  const P300Dataset data =
      buildDataset({simulatedCopyTask(5, 24)}, withMethodRate(PipelineSettings{}, "slda"));
  const CrossValidation cv = crossValidate(data, settings);
  EXPECT_GT(cv.report.auc, 0.75);
  EXPECT_LT(cv.report.auc, 0.95);
  EXPECT_LT(cv.report.accuracy.front(), 0.95);
  EXPECT_GT(cv.report.accuracy.back(), cv.report.accuracy.front());
  EXPECT_GE(cv.report.accuracy.back(), 0.85);
}

TEST(P300Model, JsonRoundTripScoresTheSameAndKeepsItsProvenance) {
  const P300Dataset data =
      buildDataset({simulatedCopyTask(6, 12)}, withMethodRate(PipelineSettings{}, "slda"));
  TrainingSettings settings;
  settings.method = "xdawn";
  const TrainingResult trained =
      trainModel(data, withMethodRate(PipelineSettings{}, "slda"), settings);
  const auto path = std::filesystem::temp_directory_path() / "arbci_model_test.json";
  trained.model.save(path);
  const P300Model loaded = P300Model::load(path);
  EXPECT_EQ(loaded.method, "xdawn");
  EXPECT_EQ(loaded.pipeline.channels, data.feature_channels);
  for (int i = 0; i < data.epochs(); i += 13) {
    EXPECT_NEAR(loaded.classifier->score(data.features.row(i).transpose()),
                trained.model.classifier->score(data.features.row(i).transpose()), 1e-9);
  }
  EXPECT_EQ(loaded.provenance.at("training_files").at(0), "simulated");
  EXPECT_EQ(loaded.provenance.at("cross_validation").at("split"), "by selection");
  EXPECT_DOUBLE_EQ(loaded.score_model.sd, trained.model.score_model.sd);
}

// A session records its photodiode (flash-locked, 1000 uV while lit) for the timing check;
// training on that recording must use the EEG alone, exactly as if the channel were not there.
TEST(P300Dataset, ASessionsPhotodiodeChannelIsNeverClassified) {
  const Recording eeg = simulatedCopyTask(6, 6);
  Recording with_diode = eeg;
  with_diode.info.channels.push_back("Photodiode");
  with_diode.parameters["PhotodiodeChannel"] = "Photodiode";
  std::vector<float> diode(static_cast<size_t>(eeg.samples), 0.0f);
  for (const StimulusEvent& e : eeg.stimuli) {
    for (std::int64_t s = e.sample;
         s < std::min<std::int64_t>(e.sample + e.duration_samples, eeg.samples); ++s)
      diode[static_cast<size_t>(s)] = 1000.0f;
  }
  with_diode.data.insert(with_diode.data.end(), diode.begin(), diode.end());
  const P300Dataset plain = buildDataset({eeg}, withMethodRate(PipelineSettings{}, "slda"));
  const P300Dataset session =
      buildDataset({with_diode}, withMethodRate(PipelineSettings{}, "slda"));
  EXPECT_EQ(session.info.channels, eeg.info.channels);
  EXPECT_EQ(session.feature_channels, plain.feature_channels);
  EXPECT_EQ(
      std::count(session.feature_channels.begin(), session.feature_channels.end(), "Photodiode"),
      0);
  ASSERT_EQ(session.features.rows(), plain.features.rows());
  ASSERT_EQ(session.features.cols(), plain.features.cols());
  EXPECT_EQ((session.features - plain.features).cwiseAbs().maxCoeff(), 0.0);
}

TEST(P300Model, RefusesTheWrongSignalAndBrokenFiles) {
  const P300Dataset data =
      buildDataset({simulatedCopyTask(6, 6)}, withMethodRate(PipelineSettings{}, "slda"));
  TrainingSettings settings;
  settings.method = "slda";
  const P300Model model =
      trainModel(data, withMethodRate(PipelineSettings{}, "slda"), settings).model;
  SignalInfo other = data.info;
  other.rate_hz = 512.0;
  EXPECT_THROW(model.checkCompatible(other, "x.bdf"), ModelError);
  other = data.info;
  other.channels[3] = "T7";
  try {
    model.checkCompatible(other, "x.bdf");
    FAIL();
  } catch (const ModelError& error) {
    EXPECT_NE(std::string(error.what()).find("no channel Pz"), std::string::npos) << error.what();
  }
  const auto path = std::filesystem::temp_directory_path() / "arbci_broken_model.json";
  nlohmann::json json = model.toJson();
  json["classifier"]["weights"].erase(0);
  std::ofstream(path) << json.dump();
  try {
    P300Model::load(path);
    FAIL();
  } catch (const ModelError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("weights"), std::string::npos) << error.what();
  }
  Recording silent = simulatedCopyTask(6, 2);
  silent.stimuli.clear();
  EXPECT_THROW(buildDataset({silent}, withMethodRate(PipelineSettings{}, "slda")),
               std::invalid_argument);
}

}  // namespace
}  // namespace arbci::bci
