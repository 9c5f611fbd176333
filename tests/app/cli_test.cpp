// The arbci command line: help, version, bad arguments, gl-info and headless screenshots.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/run_process.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

int lineCount(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

std::filesystem::path tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_cli_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(Cli, HelpListsTheSubcommands) {
  const ProcessResult result = runProcess(kArbci, {"--help"});
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find("gl-info"), std::string::npos);
  EXPECT_NE(result.out.find("screenshot"), std::string::npos);
}

TEST(Cli, VersionPrintsTheProjectVersion) {
  const ProcessResult result = runProcess(kArbci, {"--version"});
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find(ARBCI_VERSION), std::string::npos);
}

TEST(Cli, UnknownOptionGivesOneLineErrorAndNonZeroExit) {
  for (const auto& arguments : std::vector<std::vector<std::string>>{
           {"--no-such-option"},
           {"screenshot", "--headless", "--out", "x.png", "--bogus"},
           {"no-such-command"},
           {"screenshot", "--headless"}}) {
    const ProcessResult result = runProcess(kArbci, arguments);
    EXPECT_NE(result.exit_code, 0) << arguments[0];
    EXPECT_EQ(lineCount(result.err), 1) << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
  }
}

TEST(Cli, UnwritableOutputGivesOneLineErrorAndNonZeroExit) {
  const ProcessResult result =
      runProcess(kArbci, {"screenshot", "--headless", "--out", "/nonexistent-dir/shot.png"});
  EXPECT_NE(result.exit_code, 0);
  EXPECT_EQ(lineCount(result.err), 1) << result.err;
  EXPECT_NE(result.err.find("/nonexistent-dir/shot.png"), std::string::npos) << result.err;
}

// An option that cannot act is refused, not ignored.
TEST(Cli, DetectRefusesAMarkerSetWithoutACamera) {
  const ProcessResult r = runProcess(kArbci, {"detect", "--marker-set", "set.cfg", "frame.png"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--marker-set needs --camera"), std::string::npos) << r.err;
}

TEST(Cli, GlInfoHeadlessPrintsVendorRendererAndVersion) {
  const ProcessResult result = runProcess(kArbci, {"gl-info", "--headless"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("vendor:"), std::string::npos);
  EXPECT_NE(result.out.find("renderer:"), std::string::npos);
  EXPECT_NE(result.out.find("version:"), std::string::npos);
}

TEST(Cli, HeadlessScreenshotWritesAPngOfTheRequestedSizeWithItsStatusBar) {
  const auto path = tempPath("shell.png");
  std::filesystem::remove(path);
  const ProcessResult result = runProcess(
      kArbci, {"screenshot", "--headless", "--size", "1024x640", "--out", path.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1024);
  EXPECT_EQ(image.rows, 640);
  double min_value = 0, max_value = 0;
  cv::Mat gray;
  cv::extractChannel(image, gray, 1);
  cv::minMaxLoc(gray, &min_value, &max_value);
  EXPECT_GT(max_value - min_value, 100) << "the screenshot is (nearly) one colour";
  // The status bar's text is drawn: its strip holds light pixels on the dark background.
  const cv::Mat status_bar = gray.rowRange(600, 640);
  EXPECT_GT(cv::countNonZero(status_bar > 150), 50);
}

}  // namespace
}  // namespace arbci::test
