// `arbci train` and `arbci evaluate` on the BCI2000 sample data: progress, the cross-validation
// table, a model with provenance, plots and a BCI2000 fragment; 6MK? spelled; clear errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/run_process.h"
#include "support/shared_data.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_p300_cli_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::string eeg(const std::string& name) {
  return sharedData("eeg/bci2000_samplefiles/" + name);
}

TEST(TrainAndEvaluate, TrainOnEeg3_1ThenEvaluateEeg3_2) {
  const auto model = scratch("swlda.json"), prm = scratch("swlda.prm"), plots = scratch("plots");
  std::filesystem::remove_all(plots);
  ProcessResult r =
      runProcess(kArbci, {"train", "--method", "swlda", eeg("eeg3_1.dat"), "--out", model.string(),
                          "--bci2000", prm.string(), "--plots", plots.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("100%"), std::string::npos);
  EXPECT_NE(r.out.find("cross-validation, 4 folds split by selection"), std::string::npos) << r.out;
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

TEST(TrainAndEvaluate, BadInputGetsAClearError) {
  const auto model = scratch("slda.json");
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
  const auto quiet = scratch("quiet.bdf");
  ASSERT_EQ(
      runProcess(kArbci, {"eeg", "simulate", "--seconds", "3", "--out", quiet.string()}).exit_code,
      0);
  r = runProcess(kArbci, {"train", quiet.string(), "--out", scratch("none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no stimulus events"), std::string::npos) << r.err;
  // Too little to train on: a single selection.
  const auto short_file = scratch("short.bdf");
  ASSERT_EQ(runProcess(kArbci, {"eeg", "simulate", "--seconds", "10", "--out", short_file.string()})
                .exit_code,
            0);
  r = runProcess(kArbci, {"train", short_file.string(), "--out", scratch("none.json").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("at least 2 selections"), std::string::npos) << r.err;
  // A broken model file.
  std::ofstream(scratch("broken.json")) << "{\"format\": \"arbci-p300-model\"";
  r = runProcess(kArbci,
                 {"evaluate", "--model", scratch("broken.json").string(), eeg("eeg3_2.dat")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("broken.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
