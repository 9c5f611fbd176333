// `arbci train` and `arbci evaluate` on the BCI2000 sample data: progress, the cross-validation
// table, a model with provenance, plots and a BCI2000 fragment; 6MK? spelled; clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "support/run_process.h"
#include "support/shared_data.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

const std::string kScratch = "arbci_p300_cli_test";

std::string eeg(const std::string& name) {
  return sharedData("eeg/bci2000_samplefiles/" + name);
}

// A simulated copy-task recording (arbci eeg simulate), read back.
bci::Recording simulated(const std::string& name, int seconds, int seed) {
  const auto path = scratchPath(kScratch, name + "_simulated.bdf");
  const ProcessResult r =
      runProcess(kArbci, {"eeg", "simulate", "--seconds", std::to_string(seconds), "--seed",
                          std::to_string(seed), "--out", path.string()});
  if (r.exit_code != 0) throw std::runtime_error("arbci eeg simulate failed: " + r.err);
  return bci::readRecording(path.string());
}

// `recording` (its samples and stimuli) as a BDF+ file.
void write(const std::filesystem::path& path, const bci::Recording& recording) {
  bci::RecordingWriter writer(path, recording.info);
  bci::Block block(0, recording.info.channelCount(), static_cast<int>(recording.samples));
  block.data = recording.data;
  writer.write(block);
  for (const bci::StimulusEvent& e : recording.stimuli) writer.addStimulus(e);
}

// The ERP figure's numbers (erp.json) against ERPs averaged here from the raw file: every epoch of
// -100 ms (the baseline, its mean subtracted) to the window's end, averaged per class. Unfiltered,
// so nothing of ARBCI's signal path enters the reference but the file reader.
TEST(TrainAndEvaluate, ErpJsonEqualsAnIndependentAverageOfEeg3_1) {
  const auto model = scratchPath(kScratch, "erp_model.json"),
             plots = scratchPath(kScratch, "erp_plots");
  std::filesystem::remove_all(plots);
  const ProcessResult r = runProcess(
      kArbci, {"train", "--method", "slda", "--highpass-hz", "0", "--lowpass-hz", "0", "--notch-hz",
               "0", eeg("eeg3_1.dat"), "--out", model.string(), "--plots", plots.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("plot: " + (plots / "erp.json").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("plot: " + (plots / "scalp.png").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("plot: " + (plots / "r2.png").string()), std::string::npos) << r.out;
  std::ifstream in(plots / "erp.json");
  const nlohmann::json erp = nlohmann::json::parse(in);
  // What was done, stated: unfiltered (so not "zero-phase"), the amplifier's reference, the
  // scalp map inside the P300's window.
  EXPECT_EQ(erp["reference"], "as_recorded");
  EXPECT_EQ(erp["filter"]["type"], "none");
  EXPECT_EQ(erp["filter"]["zero_phase"], false);
  EXPECT_GE(erp["scalp_map"]["time_ms"].get<double>(), 250.0);
  EXPECT_LE(erp["scalp_map"]["time_ms"].get<double>(), 600.0);
  EXPECT_GT(erp["selections"].get<int>(), 0);

  const bci::Recording raw = bci::readRecording(eeg("eeg3_1.dat"));
  const int channels = raw.info.channelCount();
  const double rate = raw.info.rate_hz;
  const int baseline = static_cast<int>(std::lround(0.1 * rate));
  ASSERT_EQ(erp["channels"].size(), static_cast<size_t>(channels));
  // The span: the baseline, then the 0-800 ms window (its length as the classifier cuts it).
  const int length = static_cast<int>(erp["channels"][0]["time_ms"].size());
  EXPECT_NEAR(length - baseline, 0.8 * rate, 1.0);
  for (int i = 0; i < length; ++i)
    ASSERT_NEAR(erp["channels"][0]["time_ms"][i].get<double>(), (i - baseline) * 1000.0 / rate,
                1e-6);
  std::vector<std::vector<double>> sum[2], sum_sq[2];
  for (auto& s : sum) s.assign(channels, std::vector<double>(length, 0.0));
  for (auto& s : sum_sq) s.assign(channels, std::vector<double>(length, 0.0));
  int count[2] = {0, 0};
  for (const bci::StimulusEvent& e : raw.stimuli) {
    const std::int64_t first = e.sample - baseline;
    if (first < 0 || first + length > raw.samples) continue;
    const int k = e.target ? 0 : 1;
    ++count[k];
    for (int c = 0; c < channels; ++c) {
      const float* x = raw.data.data() + c * raw.samples + first;
      double mean = 0.0;
      for (int i = 0; i < baseline; ++i) mean += x[i];
      mean /= baseline;
      for (int i = 0; i < length; ++i) {
        sum[k][c][i] += x[i] - mean;
        sum_sq[k][c][i] += (x[i] - mean) * (x[i] - mean);
      }
    }
  }
  EXPECT_EQ(erp["target_epochs"], count[0]);
  EXPECT_EQ(erp["non_target_epochs"], count[1]);
  double worst = 0.0;
  for (int c = 0; c < channels; ++c) {
    const nlohmann::json& channel = erp["channels"][c];
    EXPECT_EQ(channel["name"], raw.info.channels[c]);
    for (int i = 0; i < length; ++i) {
      const double target = sum[0][c][i] / count[0], other = sum[1][c][i] / count[1];
      worst = std::max({worst, std::abs(channel["target"][i].get<double>() - target),
                        std::abs(channel["non_target"][i].get<double>() - other),
                        std::abs(channel["difference"][i].get<double>() - (target - other))});
    }
  }
  EXPECT_LT(worst, 0.1) << "largest difference from the independent average, uV";
  // Signed r^2 (point-biserial, squared with its sign) and the peak of the difference's RMS
  // over channels, where the scalp map is drawn.
  double worst_r2 = 0.0, peak_power = -1.0;
  int peak_sample = 0;
  const double n1 = count[0], n0 = count[1], n = n1 + n0;
  for (int i = 0; i < length; ++i) {
    double power = 0.0;
    for (int c = 0; c < channels; ++c) {
      const double m1 = sum[0][c][i] / n1, m0 = sum[1][c][i] / n0;
      const double grand = (sum[0][c][i] + sum[1][c][i]) / n;
      const double sd = std::sqrt((sum_sq[0][c][i] + sum_sq[1][c][i]) / n - grand * grand);
      const double r = (m1 - m0) * std::sqrt(n1 * n0) / (n * sd);
      worst_r2 = std::max(
          worst_r2, std::abs(erp["channels"][c]["signed_r2"][i].get<double>() - r * std::abs(r)));
      power += (m1 - m0) * (m1 - m0);
    }
    if (power > peak_power) {
      peak_power = power;
      peak_sample = i;
    }
  }
  EXPECT_LT(worst_r2, 1e-4);
  EXPECT_NEAR(erp["peak_ms"].get<double>(), (peak_sample - baseline) * 1000.0 / rate, 1e-6);
  // Fz's target average peaks positive between 150 and 350 ms (the P300 of this subject).
  const nlohmann::json& fz = erp["channels"][0];
  ASSERT_EQ(fz["name"], "Fz");
  int peak = 0;
  for (int i = 0; i < length; ++i)
    if (fz["target"][i].get<double>() > fz["target"][peak].get<double>()) peak = i;
  EXPECT_GT(fz["target"][peak].get<double>(), 5.0);
  EXPECT_GE(fz["time_ms"][peak].get<double>(), 150.0);
  EXPECT_LE(fz["time_ms"][peak].get<double>(), 350.0);
}

// The largest target - non-target difference of a channel of erp.json between `from_ms` and
// `to_ms`: {uV, ms}.
std::pair<double, double> largestDifference(const nlohmann::json& channel, double from_ms,
                                            double to_ms) {
  std::pair<double, double> best{-1e9, 0.0};
  for (size_t i = 0; i < channel["time_ms"].size(); ++i) {
    const double ms = channel["time_ms"][i].get<double>();
    const double uv = channel["difference"][i].get<double>();
    if (ms >= from_ms && ms <= to_ms && uv > best.first) best = {uv, ms};
  }
  return best;
}

// The default figure is zero-phase and shows eeg3_1's parietal P300 as a positivity at 300-500
// ms; --causal shows what the online filter makes of it (a late trough); both state the band.
TEST(TrainAndEvaluate, DefaultErpFigureShowsTheParietalP300AndStatesItsFilter) {
  const auto model = scratchPath(kScratch, "zero_phase_erp.json");
  nlohmann::json erp[2];
  for (const bool causal : {false, true}) {
    const auto plots = scratchPath(kScratch, causal ? "causal_erp_plots" : "zero_phase_erp_plots");
    std::filesystem::remove_all(plots);
    std::vector<std::string> args{"train", "--method",     "slda",    eeg("eeg3_1.dat"),
                                  "--out", model.string(), "--plots", plots.string()};
    if (causal) args.push_back("--causal");
    const ProcessResult r = runProcess(kArbci, args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(plots / "erp.json");
    erp[causal] = nlohmann::json::parse(in);
    EXPECT_EQ(erp[causal]["filter"]["highpass_hz"], 0.5);
    EXPECT_EQ(erp[causal]["filter"]["lowpass_hz"], 20.0);
    EXPECT_EQ(erp[causal]["filter"]["zero_phase"], !causal);
    EXPECT_EQ(erp[causal]["filter"]["type"], "butterworth");
    EXPECT_GT(erp[causal]["filter"]["order"].get<int>(), 0);
    EXPECT_EQ(erp[causal]["filter"]["notch_hz"], 50.0);
    EXPECT_GT(erp[causal]["filter"]["notch_q"].get<double>(), 0.0);
    // The window the features use: 15 bins of 13 samples at 256 Hz, 0-762 ms (not 800).
    EXPECT_NEAR(erp[causal]["window_ms"][1].get<double>(), 15 * 13 * 1000.0 / 256.0, 1e-6);
  }
  for (const char* name : {"Pz", "P3", "P4"}) {
    const auto channel = std::find_if(erp[0]["channels"].begin(), erp[0]["channels"].end(),
                                      [&](const nlohmann::json& c) { return c["name"] == name; });
    ASSERT_NE(channel, erp[0]["channels"].end()) << name;
    const auto [uv, ms] = largestDifference(*channel, 300.0, 500.0);
    EXPECT_GT(uv, 10.0) << name << " at " << ms << " ms";
    // The peak over the whole window is inside 300-500 ms, not at its edge.
    const auto [whole_uv, whole_ms] = largestDifference(*channel, 0.0, 800.0);
    EXPECT_GE(whole_ms, 300.0) << name;
    EXPECT_LE(whole_ms, 500.0) << name;
    EXPECT_GT(ms, 310.0) << name;
    EXPECT_LT(ms, 490.0) << name;
  }
  // Causally filtered, Pz's difference dips below zero after 500 ms (the filter's ringing).
  for (const nlohmann::json& channel : erp[1]["channels"]) {
    if (channel["name"] != "Pz") continue;
    double lowest = 0.0;
    for (size_t i = 0; i < channel["time_ms"].size(); ++i)
      if (channel["time_ms"][i].get<double>() > 500.0)
        lowest = std::min(lowest, channel["difference"][i].get<double>());
    EXPECT_LT(lowest, -5.0);
  }
}

TEST(TrainAndEvaluate, TrainOnEeg3_1ThenEvaluateEeg3_2) {
  const auto model = scratchPath(kScratch, "swlda.json"), prm = scratchPath(kScratch, "swlda.prm"),
             plots = scratchPath(kScratch, "plots");
  std::filesystem::remove_all(plots);
  ProcessResult r =
      runProcess(kArbci, {"train", "--method", "swlda", eeg("eeg3_1.dat"), "--out", model.string(),
                          "--bci2000", prm.string(), "--plots", plots.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("100%"), std::string::npos);
  EXPECT_NE(r.out.find("cross-validation, 4 folds by selection"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("selected with 15 sequences: T3OF"), std::string::npos) << r.out;
  std::ifstream in(model);
  const nlohmann::json json = nlohmann::json::parse(in);
  EXPECT_EQ(json["method"], "swlda");
  EXPECT_NE(json["provenance"]["training_files"][0].get<std::string>().find("eeg3_1.dat"),
            std::string::npos);
  EXPECT_EQ(json["provenance"]["cross_validation"]["accuracy_by_sequences"].size(), 15u);
  for (const char* plot : {"erp.png", "accuracy.png"}) {
    const cv::Mat image = cv::imread((plots / plot).string());
    ASSERT_FALSE(image.empty()) << plot;
    double low = 0, high = 0;
    cv::minMaxLoc(image.reshape(1), &low, &high);
    EXPECT_LT(low, high);
  }
  std::ifstream fragment(prm);
  std::string first;
  std::getline(fragment, first);
  EXPECT_EQ(first.rfind("Filtering:LinearClassifier matrix Classifier= ", 0), 0u);

  r = runProcess(kArbci, {"evaluate", "--model", model.string(), eeg("eeg3_2.dat")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("selected with 15 sequences: 6MK?"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("       15     1.000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dynamic stopping"), std::string::npos);
  EXPECT_NE(r.out.find("bits/min"), std::string::npos);
}

// --report holds what is printed; --scores has one row per flash with its out-of-fold score.
TEST(TrainAndEvaluate, ReportAndScoresFilesHoldWhatIsPrinted) {
  const auto model = scratchPath(kScratch, "report_model.json"),
             report = scratchPath(kScratch, "report.json"),
             scores = scratchPath(kScratch, "scores.csv");
  const ProcessResult r =
      runProcess(kArbci, {"train", "--method", "slda", eeg("eeg3_1.dat"), "--out", model.string(),
                          "--report", report.string(), "--scores", scores.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(report);
  const nlohmann::json json = nlohmann::json::parse(in);
  char auc[64];
  std::snprintf(auc, sizeof auc, "single-flash AUC: %.3f (95 %% interval [%.3f, %.3f]",
                json["auc"].get<double>(), json["auc_interval_95"][0].get<double>(),
                json["auc_interval_95"][1].get<double>());
  EXPECT_NE(r.out.find(auc), std::string::npos) << auc << "\n" << r.out;
  EXPECT_LT(json["auc_interval_95"][0].get<double>(), json["auc"].get<double>());
  EXPECT_EQ(json["folds_by"], "selection");
  EXPECT_EQ(json["target_flashes"], 120);
  EXPECT_EQ(json["non_target_flashes"], 600);
  EXPECT_EQ(json["choices"], 36);
  EXPECT_NEAR(json["chance"].get<double>(), 1.0 / 36.0, 1e-12);
  ASSERT_EQ(json["by_sequences"].size(), 15u);
  EXPECT_EQ(json["by_sequences"][14]["selected"], "T3OF");
  char row[96];
  const nlohmann::json& first = json["by_sequences"][0];
  std::snprintf(row, sizeof row, "%9d%10.3f  [%.3f, %.3f]", 1, first["accuracy"].get<double>(),
                first["accuracy_interval_95"][0].get<double>(),
                first["accuracy_interval_95"][1].get<double>());
  EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
  EXPECT_GT(json["all_inclusive"]["seconds_per_selection"].get<double>(),
            json["by_sequences"][14]["seconds_per_selection"].get<double>());

  std::ifstream csv(scores);
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "file,sample,code,label,score,fold");
  int rows = 0, targets = 0;
  std::set<int> folds;
  while (std::getline(csv, line)) {
    ++rows;
    std::vector<std::string> cells;
    std::stringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 6u) << line;
    targets += cells[3] == "1";
    folds.insert(std::stoi(cells[5]));
  }
  EXPECT_EQ(rows, 720);  // every flash of eeg3_1
  EXPECT_EQ(targets, 120);
  EXPECT_EQ(folds, (std::set<int>{0, 1, 2, 3}));  // 4 selections, 4 folds
}

// A recording whose codes are the classes (target / non-target only, as Brain Invaders or an
// oddball): single-flash AUC over contiguous blocks, and no selection metrics.
TEST(TrainAndEvaluate, ARecordingCodedByClassGetsSingleFlashMetricsOnly) {
  const auto by_class = scratchPath(kScratch, "by_class.bdf");
  bci::Recording recording = simulated("by_class", 60, 4);
  for (bci::StimulusEvent& e : recording.stimuli) e.code = e.target ? 1 : 2;
  write(by_class, recording);
  const auto report = scratchPath(kScratch, "by_class_report.json");
  const ProcessResult r = runProcess(
      kArbci, {"train", "--method", "slda", by_class.string(), "--out",
               scratchPath(kScratch, "by_class.json").string(), "--report", report.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The session's folds (classifier.folds), by block.
  EXPECT_NE(r.out.find("4 folds by block (the default here"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no selection metrics"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("bits/min"), std::string::npos) << r.out;
  std::ifstream in(report);
  const nlohmann::json json = nlohmann::json::parse(in);
  EXPECT_FALSE(json["selection_metrics"].get<bool>());
  EXPECT_FALSE(json.contains("by_sequences"));
  // The simulated subject's P300 is clear: 0.79 for this seed's 60 s (chance: 0.5).
  EXPECT_GT(json["auc"].get<double>(), 0.75);
}

// eeg2 (an oddball session per file: 20 targets, 80 non-targets) trains as one file, which used to
// fail with "cross-validation needs at least 2 selections", and is evaluated on the other session:
// the best method's single-flash AUC is at least 0.90, and no method reports selections, since
// its codes are classes (with them, unequal flash counts once made the non-target code win).
TEST(TrainAndEvaluate, OddballEeg2_1TrainsAsOneFileAndEvaluatesOnEeg2_2) {
  double best_auc = 0.0;
  for (const std::string method : {"swlda", "slda", "xdawn", "riemann"}) {
    const auto model = scratchPath(kScratch, "eeg2_" + method + ".json");
    ProcessResult r = runProcess(
        kArbci, {"train", "--method", method, eeg("eeg2_1.dat"), "--out", model.string()});
    ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
    const auto report = scratchPath(kScratch, "eeg2_" + method + "_report.json");
    r = runProcess(kArbci, {"evaluate", "--model", model.string(), eeg("eeg2_2.dat"), "--report",
                            report.string()});
    ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
    EXPECT_NE(r.out.find("no selection metrics"), std::string::npos) << r.out;
    std::ifstream in(report);
    const nlohmann::json json = nlohmann::json::parse(in);
    EXPECT_FALSE(json["selection_metrics"].get<bool>()) << method;
    EXPECT_EQ(json["target_flashes"].get<int>(), 20) << method;
    EXPECT_EQ(json["non_target_flashes"].get<int>(), 80) << method;
    best_auc = std::max(best_auc, json["auc"].get<double>());
  }
  EXPECT_GE(best_auc, 0.90);
}

// The Riemannian method with its defaults (covariances of the causally band-passed epoch at
// 64 Hz, 2 xDAWN filters per class) against an independent computation of the same pipeline:
// a BCI2000 reader of its own (the simulated files read by MNE), scipy's Butterworth and notch
// filters, numpy's xDAWN covariances (Ledoit-Wolf), Riemannian mean and tangent space as
// pyriemann computes them, and scikit-learn's shrinkage LDA. Run once by hand; its AUCs are the
// numbers below (docs/classification.md says how they were obtained).
TEST(TrainAndEvaluate, RiemannianMethodAgreesWithAnIndependentComputation) {
  const auto simulated = [](int sequences) {
    const auto path = scratchPath(kScratch, "riemann_sim7_" + std::to_string(sequences) + ".bdf");
    const ProcessResult r =
        runProcess(kArbci, {"eeg", "simulate", "--seconds", "240", "--seed", "7", "--sequences",
                            std::to_string(sequences), "--out", path.string()});
    if (r.exit_code != 0) throw std::runtime_error("arbci eeg simulate failed: " + r.err);
    return path.string();
  };
  const std::string sim_a = simulated(8), sim_b = simulated(10);
  struct Case {
    std::string train, test;
    double independent_auc;
    std::string spelled;
  };
  const std::vector<Case> cases{{eeg("eeg3_1.dat"), eeg("eeg3_2.dat"), 0.8800, "6MK?"},
                                {eeg("eeg3_2.dat"), eeg("eeg3_1.dat"), 0.8269, "T3OF"},
                                {eeg("eeg2_1.dat"), eeg("eeg2_2.dat"), 0.9231, ""},
                                {eeg("eeg2_2.dat"), eeg("eeg2_1.dat"), 0.8944, ""},
                                {sim_a, sim_b, 0.8653, ""},
                                {sim_b, sim_a, 0.8703, ""}};
  const auto model = scratchPath(kScratch, "riemann_independent.json");
  const auto report = scratchPath(kScratch, "riemann_independent_report.json");
  for (const Case& c : cases) {
    ProcessResult r =
        runProcess(kArbci, {"train", "--method", "riemann", c.train, "--out", model.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = runProcess(kArbci,
                   {"evaluate", "--model", model.string(), c.test, "--report", report.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(report);
    const double auc = nlohmann::json::parse(in)["auc"].get<double>();
    EXPECT_NEAR(auc, c.independent_auc, 0.02) << c.train << " -> " << c.test;
    if (!c.spelled.empty()) {
      EXPECT_NE(r.out.find("selected with 15 sequences: " + c.spelled), std::string::npos) << r.out;
    }
    if (c.spelled == "6MK?") {
      EXPECT_GE(auc, 0.86);
    }
  }
}

// The Riemannian method through the CLI: trained, saved, loaded and applied to the other session.
TEST(TrainAndEvaluate, RiemannianModelSpellsTheOtherSession) {
  const auto model = scratchPath(kScratch, "riemann.json");
  ProcessResult r = runProcess(
      kArbci, {"train", "--method", "riemann", eeg("eeg3_1.dat"), "--out", model.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(model);
  EXPECT_EQ(nlohmann::json::parse(in)["classifier"]["method"], "riemann");
  const auto report = scratchPath(kScratch, "riemann_report.json");
  r = runProcess(kArbci, {"evaluate", "--model", model.string(), eeg("eeg3_2.dat"), "--report",
                          report.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("selected with 15 sequences: 6MK?"), std::string::npos) << r.out;
  std::ifstream report_in(report);
  EXPECT_GT(nlohmann::json::parse(report_in)["auc"].get<double>(), 0.85);
  // Not linear (the classifiers' entries say so): no BCI2000 fragment, refused before training.
  for (const char* method : {"riemann", "shift-lda"}) {
    r = runProcess(kArbci, {"train", "--method", method, eeg("eeg3_1.dat"), "--out", model.string(),
                            "--bci2000", scratchPath(kScratch, "riemann.prm").string()});
    EXPECT_EQ(r.exit_code, 1) << method;
    EXPECT_NE(r.err.find("not linear"), std::string::npos) << r.err;
  }
}

// Flat and drifting channels are reported, and left out on request; epochs over an amplitude
// limit are rejected and counted; zero-phase filtering is recorded in the model.
TEST(TrainAndEvaluate, BadChannelsAndLargeEpochsAreReportedAndLeftOutOnRequest) {
  const auto damaged = scratchPath(kScratch, "artifacts.bdf");
  const bci::Recording clean = simulated("artifacts", 90, 5);
  const std::string flat = clean.info.channels[1], drifting = clean.info.channels[2];
  bci::Recording broken = clean;
  for (std::int64_t s = 0; s < broken.samples; ++s) {
    broken.data[static_cast<size_t>(1 * broken.samples + s)] = 0.0f;  // a shorted electrode
    broken.data[static_cast<size_t>(2 * broken.samples + s)] +=
        static_cast<float>(1e5 * s / broken.samples);  // a contact drifting by 1e5 uV
  }
  write(damaged, broken);
  const auto model = scratchPath(kScratch, "artifacts.json"),
             report = scratchPath(kScratch, "artifacts_report.json");
  const auto plain_plots = scratchPath(kScratch, "artifacts_plots"),
             car_plots = scratchPath(kScratch, "artifacts_car_plots");
  std::filesystem::remove_all(plain_plots);
  std::filesystem::remove_all(car_plots);
  ProcessResult r = runProcess(kArbci, {"train", "--method", "slda", damaged.string(), "--out",
                                        model.string(), "--plots", plain_plots.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("channels: flat " + flat + "; drifting " + drifting +
                       ": used (--exclude-bad-channels to leave them out)"),
            std::string::npos)
      << r.out;
  r = runProcess(kArbci, {"train", "--method", "slda", damaged.string(), "--out", model.string(),
                          "--exclude-bad-channels", "--reject-uv", "60", "--zero-phase", "--report",
                          report.string(), "--car", "--plots", car_plots.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The figures' numbers say what was done: the reference, and the channels left out and why.
  auto erpOf = [](const std::filesystem::path& plots) {
    std::ifstream in(plots / "erp.json");
    return nlohmann::json::parse(in);
  };
  const nlohmann::json plain = erpOf(plain_plots), car = erpOf(car_plots);
  EXPECT_EQ(plain["reference"], "as_recorded");
  EXPECT_EQ(plain["excluded_channels"], nlohmann::json::array());
  EXPECT_EQ(car["reference"], "common_average");
  EXPECT_EQ(
      car["excluded_channels"],
      nlohmann::json::parse("[{\"name\": \"" + flat + "\", \"why\": \"flat\"}, {\"name\": \"" +
                            drifting + "\", \"why\": \"drifting\"}]"));
  EXPECT_NE(r.out.find(": excluded"), std::string::npos) << r.out;
  std::ifstream model_in(model);
  const nlohmann::json m = nlohmann::json::parse(model_in);
  const auto channels = m["pipeline"]["channels"].get<std::vector<std::string>>();
  EXPECT_EQ(channels.size(), clean.info.channels.size() - 2);
  EXPECT_EQ(std::count(channels.begin(), channels.end(), flat), 0);
  EXPECT_EQ(std::count(channels.begin(), channels.end(), drifting), 0);
  EXPECT_TRUE(m["pipeline"]["zero_phase"].get<bool>());
  std::ifstream report_in(report);
  const nlohmann::json j = nlohmann::json::parse(report_in);
  EXPECT_EQ(j["channels"]["flat"], nlohmann::json::array({flat}));
  EXPECT_EQ(j["channels"]["drifting"], nlohmann::json::array({drifting}));
  const int rejected = j["rejected_epochs"].get<int>();
  EXPECT_GT(rejected, 0);  // the simulated subject blinks
  EXPECT_EQ(j["target_flashes"].get<int>() + j["non_target_flashes"].get<int>() + rejected,
            static_cast<int>(clean.stimuli.size()));
  EXPECT_NE(r.out.find(std::to_string(rejected) + " epochs over 60 uV peak-to-peak rejected"),
            std::string::npos)
      << r.out;
}

// Zero-phase filters take the causal filter's phase lag out of offline analysis: on eeg3 every
// linear method gains AUC from eeg3_1 to eeg3_2.
TEST(TrainAndEvaluate, ZeroPhaseFilteringRaisesTheOfflineAucOnEeg3) {
  for (const char* method : {"swlda", "slda"}) {
    double auc[2] = {0.0, 0.0};
    for (int zero_phase = 0; zero_phase < 2; ++zero_phase) {
      const auto model = scratchPath(kScratch, std::string("zp_") + method + ".json"),
                 report = scratchPath(kScratch, std::string("zp_") + method + "_report.json");
      std::vector<std::string> args = {"train",           "--method", method,
                                       eeg("eeg3_1.dat"), "--out",    model.string()};
      if (zero_phase) args.push_back("--zero-phase");
      ASSERT_EQ(runProcess(kArbci, args).exit_code, 0);
      ASSERT_EQ(runProcess(kArbci, {"evaluate", "--model", model.string(), eeg("eeg3_2.dat"),
                                    "--report", report.string()})
                    .exit_code,
                0);
      std::ifstream in(report);
      auc[zero_phase] = nlohmann::json::parse(in)["auc"].get<double>();
    }
    EXPECT_GT(auc[1], auc[0] + 0.005) << method;
  }
}

// Flashes of free choices are recorded as "U" (target unknown), read back as such, and left out
// of training with a count.
TEST(TrainAndEvaluate, FlashesWithUnknownTargetsAreLeftOutAndCounted) {
  const auto mixed = scratchPath(kScratch, "unknown.bdf");
  bci::Recording recording = simulated("unknown", 60, 6);
  int unknown = 0;
  for (bci::StimulusEvent& e : recording.stimuli) {
    e.known = e.sample <= recording.samples / 2;  // the second half: free choices
    unknown += !e.known;
  }
  write(mixed, recording);
  ASSERT_GT(unknown, 0);
  const bci::Recording read = bci::readRecording(mixed.string());
  EXPECT_EQ(std::count_if(read.stimuli.begin(), read.stimuli.end(),
                          [](const bci::StimulusEvent& e) { return !e.known; }),
            unknown);
  const ProcessResult r = runProcess(kArbci, {"train", "--method", "slda", mixed.string(), "--out",
                                              scratchPath(kScratch, "u.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("; " + std::to_string(unknown) +
                       " flashes whose target is not known (labelled U) left out"),
            std::string::npos)
      << r.out;
}

// A model scores its own layout's choices: evaluated on a recording of another layout (as an XDF
// without ARBCI's marker description reads), it is refused with both layouts named.
TEST(TrainAndEvaluate, ARecordingOfAnotherLayoutThanTheModelsIsRefusedNamingBoth) {
  const auto grid = scratchPath(kScratch, "grid_3x3.bdf"),
             single = scratchPath(kScratch, "single_4.bdf");
  ASSERT_EQ(runProcess(kArbci, {"eeg", "simulate", "--seconds", "90", "--rows", "3", "--columns",
                                "3", "--out", grid.string()})
                .exit_code,
            0);
  ASSERT_EQ(runProcess(kArbci, {"eeg", "simulate", "--seconds", "30", "--seed", "2", "--out",
                                single.string()})
                .exit_code,
            0);
  const auto model = scratchPath(kScratch, "grid_3x3.json");
  ASSERT_EQ(runProcess(kArbci, {"train", grid.string(), "--out", model.string()}).exit_code, 0);
  const ProcessResult r =
      runProcess(kArbci, {"evaluate", single.string(), "--model", model.string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("is a single stimulus, 4 stimuli recording, but the model was trained on "
                       "row/column 3x3 recordings"),
            std::string::npos)
      << r.err;
}

// A rejection limit that every epoch exceeds leaves nothing to train on, and says so.
TEST(TrainAndEvaluate, ALimitThatRejectsEveryEpochSaysSo) {
  const auto file = scratchPath(kScratch, "reject_all.bdf");
  write(file, simulated("reject_all", 30, 4));
  const ProcessResult r = runProcess(kArbci, {"train", file.string(), "--reject-uv", "1", "--out",
                                              scratchPath(kScratch, "reject_all.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("is over the rejection limit of 1 uV peak-to-peak: nothing is left"),
            std::string::npos)
      << r.err;
}

TEST(TrainAndEvaluate, BadInputGetsAClearError) {
  const auto model = scratchPath(kScratch, "slda.json");
  ASSERT_EQ(
      runProcess(kArbci, {"train", "--method", "slda", eeg("eeg3_1.dat"), "--out", model.string()})
          .exit_code,
      0);
  // A model for other channels.
  ProcessResult r = runProcess(
      kArbci, {"evaluate", "--model", model.string(), eeg("P3SpellerS001R01_synthetic.dat")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("has no channel Fz"), std::string::npos) << r.err;
  // A file without stimuli.
  const auto quiet = scratchPath(kScratch, "quiet.bdf");
  ASSERT_EQ(
      runProcess(kArbci, {"eeg", "simulate", "--seconds", "3", "--out", quiet.string()}).exit_code,
      0);
  r = runProcess(kArbci,
                 {"train", quiet.string(), "--out", scratchPath(kScratch, "none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no stimulus events"), std::string::npos) << r.err;
  // Folds by selection need two selections; one selection is cross-validated by block instead.
  const auto short_file = scratchPath(kScratch, "short.bdf");
  ASSERT_EQ(runProcess(kArbci, {"eeg", "simulate", "--seconds", "10", "--out", short_file.string()})
                .exit_code,
            0);
  r = runProcess(kArbci, {"train", short_file.string(), "--folds-by", "selection", "--out",
                          scratchPath(kScratch, "none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("at least 2 selections"), std::string::npos) << r.err;
  r = runProcess(kArbci, {"train", short_file.string(), "--folds-by", "file", "--out",
                          scratchPath(kScratch, "none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("by file needs at least 2 files"), std::string::npos) << r.err;
  // Numeric options out of range are refused with the option's name.
  for (const auto& [option, expected] :
       std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--certainty", "2"}, "--certainty"},
           {{"--xdawn-filters", "-1"}, "--xdawn-filters"},
           {{"--xdawn-filters", "99"}, "--xdawn-filters"},
           {{"--method", "xdawn", "--xdawn-filters", "20"}, "the features have 8 channels"},
           {{"--decimate-hz", "1000"}, "--decimate-hz"},
           {{"--decimate-hz", "400"}, "exceeds the signal's rate 256 Hz"},
           {{"--p-enter", "0.2", "--p-remove", "0.1"}, "--p-remove = 0.1 must exceed --p-enter"},
           {{"--folds-by", "trial"}, "--folds-by"}}) {
    std::vector<std::string> args = {"train", eeg("eeg3_1.dat"), "--out",
                                     scratchPath(kScratch, "bad.json").string()};
    args.insert(args.end(), option.begin(), option.end());
    r = runProcess(kArbci, args);
    EXPECT_NE(r.exit_code, 0) << option[0];  // 1, or CLI11's code for a bad option value
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  }
  // Outputs that cannot be written are refused before any training.
  r = runProcess(kArbci,
                 {"train", eeg("eeg3_1.dat"), "--out", scratchPath(kScratch, "m.json").string(),
                  "--plots", "/proc/arbci-plots"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/proc/arbci-plots"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("fold 1"), std::string::npos) << "trained before failing: " << r.err;
  // A broken model file.
  std::ofstream(scratchPath(kScratch, "broken.json")) << "{\"format\": \"arbci-p300-model\"";
  r = runProcess(kArbci, {"evaluate", "--model", scratchPath(kScratch, "broken.json").string(),
                          eeg("eeg3_2.dat")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("broken.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
