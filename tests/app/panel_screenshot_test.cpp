// `arbci screenshot --headless --panel ...` on a simulated session's live data: the path a person
// takes to picture a panel. Each panel's own contents are checked in process against a stand-in
// model (tests/ui/panels_test.cpp, milliseconds a panel); here two pictures that need the live
// session — the model it trained and the HMD view it renders — are taken and their contents
// probed.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/run_process.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

cv::Mat screenshot(const std::string& panel) {
  const auto out = std::filesystem::temp_directory_path() / ("arbci_panel_" + panel + ".png");
  std::filesystem::remove(out);
  const ProcessResult r = runProcess(
      kArbci,
      {"screenshot", "--headless", "--panel", panel, "--size", "1000x700", "--out", out.string()},
      300.0);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return cv::imread(out.string());  // BGR
}

int count(const cv::Mat& bgr, const std::function<bool(const cv::Vec3b&)>& pick) {
  int n = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) n += pick(bgr.at<cv::Vec3b>(y, x));
  }
  return n;
}

TEST(PanelScreenshot, TheTrainingPanelPlotsTheSessionsTargetAndNonTargetAverages) {
  const cv::Mat image = screenshot("session-model");
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.size(), cv::Size(1000, 700));
  // Eight channel plots, each with a red target and a blue non-target average and their bands.
  const int red =
      count(image, [](const cv::Vec3b& p) { return p[2] > 170 && p[1] < 90 && p[0] < 90; });
  const int blue = count(image, [](const cv::Vec3b& p) { return p[0] > 170 && p[2] < 120; });
  EXPECT_GT(red, 1000);
  EXPECT_GT(blue, 1000);
}

// The EEG panel on the simulated subject's live signal: every channel graded (green marks), the
// photodiode in yellow.
TEST(PanelScreenshot, TheEegPanelShowsTheLiveChannelsWithTheirQuality) {
  const cv::Mat image = screenshot("eeg");
  ASSERT_FALSE(image.empty());
  const int green = count(image, [](const cv::Vec3b& p) {
    return std::abs(p[2] - 70) < 12 && std::abs(p[1] - 190) < 12 && std::abs(p[0] - 90) < 12;
  });
  const int yellow = count(image, [](const cv::Vec3b& p) {
    return std::abs(p[2] - 230) < 15 && std::abs(p[1] - 210) < 15 && std::abs(p[0] - 90) < 15;
  });
  EXPECT_GT(green, 300);
  EXPECT_GT(yellow, 100);
}

TEST(PanelScreenshot, TheHmdViewShowsBothEyesWithThePhotodiodePatchAndTheGrid) {
  const cv::Mat image = screenshot("hmd");
  ASSERT_FALSE(image.empty());
  ASSERT_EQ(image.size(), cv::Size(1280, 480));  // the HMD view itself, both eyes
  for (const int eye : {0, 640}) {
    const cv::Mat half = image(cv::Rect(eye, 0, 640, 480));
    // The photodiode patch sits in each eye's top-left corner (dark between flashes, white on).
    const cv::Scalar patch = cv::mean(half(cv::Rect(2, 2, 24, 24)));
    const cv::Scalar table = cv::mean(half(cv::Rect(40, 360, 200, 100)));
    EXPECT_TRUE(patch[0] < 30 || patch[0] > 225) << "eye at x=" << eye << ": " << patch;
    EXPECT_GT(table[0], 80) << "eye at x=" << eye;  // the table, grey
    // The phase-2 grid's light lines on the grey table (about 150) in the middle of the view.
    const int white = count(half(cv::Rect(150, 100, 350, 240)), [](const cv::Vec3b& p) {
      return p[0] > 200 && p[1] > 200 && p[2] > 200;
    });
    EXPECT_GT(white, 400) << "eye at x=" << eye;
  }
}

TEST(PanelScreenshotErrors, AnUnknownPanelIsRefused) {
  const ProcessResult r =
      runProcess(kArbci, {"screenshot", "--headless", "--panel", "mixer", "--out", "/tmp/x.png"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--panel"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
