// `arbci detect` and `arbci marker`: one JSON line per frame in the documented form, errors on
// stderr without stopping, printable markers that detect as their ids.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "support/run_process.h"
#include "support/shared_data.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_marker_cli_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::vector<nlohmann::json> jsonLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

TEST(DetectCommand, PrintsOneJsonObjectPerFrameWithMarkersAndStageTimes) {
  const std::string samples = sharedData("vision/artoolkitplus_samples/");
  const ProcessResult result = runProcess(
      kArbci, {"detect", "--kind", "simple", "--border", "0.25", "--threshold", "150", "--raw",
               "320x240", "--repeat", "3", samples + "image_320_240_8_marker_id_simple_nr031.raw",
               samples + "image_320_240_8_marker_id_simple_nr321.raw"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto lines = jsonLines(result.out);
  ASSERT_EQ(lines.size(), 2u);
  const int expected_ids[] = {31, 321};
  for (size_t i = 0; i < 2; ++i) {
    const nlohmann::json& frame = lines[i];
    EXPECT_EQ(frame["width"], 320);
    EXPECT_EQ(frame["height"], 240);
    EXPECT_EQ(frame["threshold"], 150);
    ASSERT_EQ(frame["markers"].size(), 1u);
    const nlohmann::json& marker = frame["markers"][0];
    EXPECT_EQ(marker["id"], expected_ids[i]);
    EXPECT_EQ(marker["kind"], "simple");
    ASSERT_EQ(marker["corners"].size(), 4u);
    EXPECT_GT(marker["confidence"].get<double>(), 0.9);
    for (const char* stage : {"total", "convert", "threshold", "label", "quads", "decode"}) {
      EXPECT_TRUE(frame["timing_us"].contains(stage)) << stage;
    }
  }
  // nr031's printed top-left corner comes first.
  EXPECT_NEAR(lines[0]["markers"][0]["corners"][0][0].get<double>(), 215.9, 1.0);
  EXPECT_NEAR(lines[0]["markers"][0]["corners"][0][1].get<double>(), 148.4, 1.0);
}

TEST(DetectCommand, ReportsUnreadableInputsAndGoesOn) {
  const auto corrupt = scratch("corrupt.png");
  std::ofstream(corrupt) << "not a png";
  const auto short_raw = scratch("short.raw");
  std::ofstream(short_raw) << "too short";
  const ProcessResult result =
      runProcess(kArbci, {"detect", "/nonexistent/frame.png", corrupt.string(),
                          sharedData("vision/opencv_contrib_aruco_tutorial/board.png")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(jsonLines(result.out).size(), 1u) << "the readable frame is still processed";
  EXPECT_NE(result.err.find("/nonexistent/frame.png"), std::string::npos);
  EXPECT_NE(result.err.find("corrupt.png"), std::string::npos);
  const ProcessResult raw = runProcess(kArbci, {"detect", "--raw", "320x240", short_raw.string()});
  EXPECT_EQ(raw.exit_code, 1);
  EXPECT_NE(raw.err.find("76800 bytes"), std::string::npos) << raw.err;
  const ProcessResult bad = runProcess(kArbci, {"detect", "--threshold", "300", corrupt.string()});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--threshold"), std::string::npos) << bad.err;
}

TEST(DetectCommand, DictionaryKindsAndAnnotation) {
  const auto folder = scratch("annotated");
  std::filesystem::remove_all(folder);
  const ProcessResult result = runProcess(
      kArbci, {"detect", "--kind", "aruco", "--annotate", folder.string(),
               sharedData("vision/opencv_contrib_aruco_tutorial/singlemarkersoriginal.jpg")});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(jsonLines(result.out)[0]["markers"].size(), 6u);
  const cv::Mat annotated = cv::imread((folder / "singlemarkersoriginal.png").string());
  EXPECT_EQ(annotated.cols, 640);
}

TEST(MarkerCommand, WritesPrintScaleMarkersThatDetectAsTheirIds) {
  const auto base = scratch("bch_0042");
  const ProcessResult make = runProcess(kArbci, {"marker", "make", "--kind", "bch", "--id", "42",
                                                 "--size-mm", "50", "--out", base.string()});
  ASSERT_EQ(make.exit_code, 0) << make.err;
  const cv::Mat png = cv::imread(base.string() + ".png", cv::IMREAD_GRAYSCALE);
  // 50 mm + two 6.25 mm quiet zones at 300 dpi.
  EXPECT_NEAR(png.cols, (50.0 + 2 * 6.25) / 25.4 * 300, 1.0);
  std::ifstream svg(base.string() + ".svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("width=\"62.5mm\""), std::string::npos);
  const ProcessResult detect = runProcess(kArbci, {"detect", base.string() + ".png"});
  ASSERT_EQ(detect.exit_code, 0) << detect.err;
  const auto markers = jsonLines(detect.out)[0]["markers"];
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0]["id"], 42);
}

TEST(MarkerCommand, ASheetHoldsEveryIdAndHazardousIdsAreWarnedAbout) {
  const auto base = scratch("sheet");
  const ProcessResult make =
      runProcess(kArbci, {"marker", "make", "--kind", "simple", "--border", "0.25", "--id",
                          "3,7,10-12", "--size-mm", "40", "--sheet", "--out", base.string()});
  ASSERT_EQ(make.exit_code, 0) << make.err;
  const ProcessResult detect =
      runProcess(kArbci, {"detect", "--kind", "simple", base.string() + ".png"});
  const auto lines = jsonLines(detect.out);
  ASSERT_EQ(lines.size(), 1u) << detect.err;
  std::vector<int> ids;
  for (const auto& m : lines[0]["markers"]) ids.push_back(m["id"]);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<int>{3, 7, 10, 11, 12}));
  const ProcessResult hazard = runProcess(
      kArbci, {"marker", "make", "--kind", "bch", "--id", "1550", "--out", scratch("h").string()});
  EXPECT_EQ(hazard.exit_code, 0);
  EXPECT_NE(hazard.err.find("1550"), std::string::npos);
  const ProcessResult out_of_range = runProcess(
      kArbci,
      {"marker", "make", "--kind", "simple", "--id", "512", "--out", scratch("x").string()});
  EXPECT_NE(out_of_range.exit_code, 0);
  EXPECT_NE(out_of_range.err.find("512"), std::string::npos);
}

}  // namespace
}  // namespace arbci::test
