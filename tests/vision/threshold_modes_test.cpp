// Threshold modes: constant, automatic (ARToolKitPlus's midrange and the original system's
// median) with random re-acquisition, vignetting compensation, and adaptive.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"
#include "support/marker_scoring.h"
#include "support/posed_markers.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

// Two BCH markers on a light card: one in the centre, one near the top-left corner.
cv::Mat card(float corner_gain) {
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(235));
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, 100, 8),
                   {{{250, 170}, {390, 170}, {390, 310}, {250, 310}}});
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, 200, 8),
                   {{{20, 20}, {120, 20}, {120, 120}, {20, 120}}});
  // Radial fall-off: gain 1 at the centre, `corner_gain` at the corners.
  cv::Mat f;
  frame.convertTo(f, CV_32F);
  const cv::Point2f centre(319.5f, 239.5f);
  const float corner = static_cast<float>(cv::norm(centre));
  for (int y = 0; y < f.rows; ++y) {
    for (int x = 0; x < f.cols; ++x) {
      const float r = static_cast<float>(cv::norm(
                          cv::Point2f(static_cast<float>(x), static_cast<float>(y)) - centre)) /
                      corner;
      f.at<float>(y, x) *= 1.0f - (1.0f - corner_gain) * r * r;
    }
  }
  f.convertTo(frame, CV_8U);
  return frame;
}

ThresholdSettings settings(ThresholdMode mode, int value = 100) {
  ThresholdSettings s;
  s.mode = mode;
  s.value = value;
  return s;
}

std::vector<int> ids(const DetectionResult& result) {
  std::vector<int> out;
  for (const auto& m : result.markers) out.push_back(m.id);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ThresholdModes, ConstantUsesAndReportsItsValue) {
  DetectorConfig config;
  config.threshold.mode = ThresholdMode::Constant;
  config.threshold.value = 128;
  MarkerDetector detector(config);
  const DetectionResult found = detector.detect(card(1.0f));
  EXPECT_EQ(found.threshold, 128);
  EXPECT_EQ(ids(found), (std::vector<int>{100, 200}));
  detector.setThreshold(settings(ThresholdMode::Constant, 5));
  const DetectionResult too_low = detector.detect(card(1.0f));
  EXPECT_EQ(too_low.threshold, 5);
  EXPECT_TRUE(too_low.markers.empty());
}

// The stage times of a frame add up to its total (what no stage timed is "other"); of repeated
// timings, medianRun() keeps one whole run, the one with the median total.
TEST(StageTimes, PartsAddUpToTheTotalAndTheMedianRunIsWhole) {
  DetectorConfig config;
  config.threshold.mode = ThresholdMode::Adaptive;
  MarkerDetector detector(config);
  std::vector<StageTimes> runs;
  for (int i = 0; i < 5; ++i) {
    const StageTimes t = detector.detect(card(0.6f)).timing;
    double parts = 0.0;
    for (const auto& [name, part] : kStageParts) {
      EXPECT_GE(t.*part, 0.0) << name;
      parts += t.*part;
    }
    EXPECT_GT(t.total, 0.0);
    EXPECT_NEAR(parts, t.total, 1e-6 * t.total);
    runs.push_back(t);
  }
  const StageTimes median = medianRun(runs);
  int below = 0, above = 0;
  bool one_of_them = false;
  for (const StageTimes& t : runs) {
    below += t.total < median.total;
    above += t.total > median.total;
    one_of_them |= t.total == median.total && t.label == median.label && t.quads == median.quads;
  }
  EXPECT_TRUE(one_of_them);
  EXPECT_LE(below, 2);
  EXPECT_LE(above, 2);
  EXPECT_EQ(medianRun({}).total, 0.0);
}

TEST(ThresholdModes, VignettingCompensationRecoversTheDarkCorner) {
  const cv::Mat frame = card(0.25f);  // the corner marker's paper is ~60 grey levels
  DetectorConfig config;
  config.threshold.mode = ThresholdMode::Constant;
  config.threshold.value = 110;
  MarkerDetector plain(config);
  EXPECT_EQ(ids(plain.detect(frame)), (std::vector<int>{100}));
  config.threshold.vignetting = Vignetting{-80, -40, -40};
  MarkerDetector compensated(config);
  const DetectionResult result = compensated.detect(frame);
  EXPECT_EQ(ids(result), (std::vector<int>{100, 200}));
  EXPECT_NE(result.threshold_mode.find("vignetting"), std::string::npos);
}

class AutomaticThreshold : public testing::TestWithParam<ThresholdMode> {};

TEST_P(AutomaticThreshold, ReacquiresALostMarkerWithinAFewFramesAndThenFollowsIt) {
  DetectorConfig config;
  config.threshold.mode = GetParam();
  config.threshold.value = 3;              // nothing is dark: the marker is lost
  config.threshold.retries_per_frame = 0;  // one random threshold per frame, as the original system
  config.threshold.random_seed = 2024;
  MarkerDetector detector(config);
  const cv::Mat frame = card(1.0f);
  int frames_to_acquire = -1;
  std::vector<int> thresholds;
  for (int f = 0; f < 20; ++f) {
    const DetectionResult result = detector.detect(frame);
    thresholds.push_back(result.threshold);
    if (!result.markers.empty() && frames_to_acquire < 0) frames_to_acquire = f;
  }
  ASSERT_GE(frames_to_acquire, 1) << "found with threshold 3";
  EXPECT_LE(frames_to_acquire, 6);
  // While lost, a different random threshold each frame.
  for (int f = 1; f < frames_to_acquire; ++f) EXPECT_NE(thresholds[f], thresholds[f - 1]);
  // Once found, the next threshold comes from the markers and keeps them found.
  const DetectionResult settled = detector.detect(frame);
  EXPECT_EQ(ids(settled), (std::vector<int>{100, 200}));
  EXPECT_GT(settled.threshold, 60);
  EXPECT_LT(settled.threshold, 200);
  // Each frame reports the threshold it used: the one carried over from the frame before.
  const int carried = detector.currentThreshold();
  EXPECT_EQ(detector.detect(frame).threshold, carried);
}

TEST_P(AutomaticThreshold, RetriesWithinTheFrameAsArToolKitPlus) {
  DetectorConfig config;
  config.threshold.mode = GetParam();
  config.threshold.value = 3;
  config.threshold.retries_per_frame = 2;
  config.threshold.random_seed = 99;
  MarkerDetector detector(config);
  int found_in = -1;
  for (int f = 0; f < 10 && found_in < 0; ++f) {
    const DetectionResult result = detector.detect(card(1.0f));
    if (!result.markers.empty()) found_in = f;
    EXPECT_LE(result.threshold_attempts, 3);
  }
  EXPECT_GE(found_in, 0);
  EXPECT_LE(found_in, 3);
}

INSTANTIATE_TEST_SUITE_P(Modes, AutomaticThreshold,
                         testing::Values(ThresholdMode::AutoMidrange, ThresholdMode::AutoMedian),
                         [](const auto& info) {
                           std::string name = toString(info.param);
                           std::erase(name, '-');
                           return name;
                         });

TEST(ThresholdModes, AdaptiveFindsWhatNoSingleThresholdCan) {
  // One marker under glare (its black is ~85), one in deep shadow (its white is ~50): no global
  // threshold separates both markers from their papers.
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(235));
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, 300, 8),
                   {{{60, 140}, {260, 140}, {260, 340}, {60, 340}}});
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, 400, 8),
                   {{{380, 140}, {580, 140}, {580, 340}, {380, 340}}});
  cv::Mat f;
  frame.convertTo(f, CV_32F);
  f(cv::Rect(0, 0, 320, 480)) = f(cv::Rect(0, 0, 320, 480)) * 0.7 + 80.0;  // glare
  f(cv::Rect(320, 0, 320, 480)) *= 0.21;                                   // shadow
  f.convertTo(frame, CV_8U);
  for (int value = 0; value <= 255; value += 5) {
    DetectorConfig config;
    config.threshold = settings(ThresholdMode::Constant, value);
    MarkerDetector detector(config);
    EXPECT_LT(detector.detect(frame).markers.size(), 2u) << "constant " << value << " found both";
  }
  MarkerDetector adaptive(DetectorConfig{});
  EXPECT_EQ(ids(adaptive.detect(frame)), (std::vector<int>{300, 400}));
}

}  // namespace
}  // namespace arbci::vision

namespace arbci::vision {
namespace {

// The case: a readable, high-contrast 71 px BCH marker tilted 55 degrees (border about 25
// grey, surround about 212, noise sigma 12), read at every constant threshold from 100 to 170.
cv::Mat tiltedMarker() {
  const cv::Matx33d camera(800, 0, 320, 0, 800, 240, 0, 0, 1);
  Pose pose;
  pose.rotation = test::markerRotation(55.0, 30.0, 10.0);
  pose.translation = {0.0, 0.0, 0.563};  // a 50 mm marker about 71 px across
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(255));
  test::drawPosedMarker(frame, camera, pose, 0.05, test::MarkerFamily::ArbciBch, 100);
  cv::Mat levels;
  frame.convertTo(levels, CV_32F, (212.0 - 25.0) / 255.0, 25.0);
  cv::Mat noise(levels.size(), CV_32F);
  cv::RNG random(7);
  random.fill(noise, cv::RNG::NORMAL, 0.0, 12.0);
  levels += noise;
  cv::Mat out;
  levels.convertTo(out, CV_8U);
  return out;
}

TEST(ThresholdModes, AReadableTiltedMarkerIsFoundAtEveryThresholdFrom100To170) {
  const cv::Mat frame = tiltedMarker();
  std::vector<int> missed;
  for (int t = 100; t <= 170; t += 5) {
    DetectorConfig config;
    config.threshold = settings(ThresholdMode::Constant, t);
    MarkerDetector detector(config);
    if (ids(detector.detect(frame)) != std::vector<int>{100}) missed.push_back(t);
  }
  EXPECT_TRUE(missed.empty()) << "missed at " << ::testing::PrintToString(missed);
  DetectorConfig adaptive;
  EXPECT_EQ(ids(MarkerDetector(adaptive).detect(frame)), std::vector<int>{100});
}

}  // namespace
}  // namespace arbci::vision
