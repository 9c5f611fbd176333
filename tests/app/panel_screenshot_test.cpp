// `arbci screenshot --headless --panel ...`: every experimenter panel, and the HMD view, rendered
// headless on a simulated session's live data.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/run_process.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

class PanelScreenshot : public ::testing::TestWithParam<std::string> {};

TEST_P(PanelScreenshot, RendersThePanelOnLiveData) {
  const auto out = std::filesystem::temp_directory_path() / ("arbci_panel_" + GetParam() + ".png");
  std::filesystem::remove(out);
  const ProcessResult r = runProcess(kArbci,
                                     {"screenshot", "--headless", "--panel", GetParam(), "--size",
                                      "1000x700", "--out", out.string()},
                                     120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat image = cv::imread(out.string());
  ASSERT_FALSE(image.empty());
  if (GetParam() == "hmd") {
    EXPECT_EQ(image.size(), cv::Size(1280, 480));  // the HMD view itself, both eyes
  } else {
    EXPECT_EQ(image.size(), cv::Size(1000, 700));
  }
  cv::Scalar mean, deviation;
  cv::meanStdDev(image, mean, deviation);
  EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 30.0);  // not one flat colour
}

INSTANTIATE_TEST_SUITE_P(Panels, PanelScreenshot,
                         ::testing::Values("threshold", "calibration", "training", "session-model",
                                           "robot", "session", "hmd"));

TEST(PanelScreenshotErrors, AnUnknownPanelIsRefused) {
  const ProcessResult r =
      runProcess(kArbci, {"screenshot", "--headless", "--panel", "mixer", "--out", "/tmp/x.png"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--panel"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
