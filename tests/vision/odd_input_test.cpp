// Odd input gives no detections or a clear error, never a crash: empty, tiny, huge, striped,
// random images, and every configuration value out of range.
#include <gtest/gtest.h>

#include <random>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"

namespace arbci::vision {
namespace {

TEST(OddInput, EmptyTinyAndDegenerateImagesGiveNoMarkers) {
  MarkerDetector detector(DetectorConfig{});
  EXPECT_TRUE(detector.detect(cv::Mat()).markers.empty());
  for (int side : {1, 2, 3, 4, 7, 16}) {
    EXPECT_TRUE(detector.detect(cv::Mat(side, side, CV_8UC1, cv::Scalar(0))).markers.empty());
    EXPECT_TRUE(detector.detect(cv::Mat(side, 1, CV_8UC1, cv::Scalar(255))).markers.empty());
    EXPECT_TRUE(detector.detect(cv::Mat(1, side, CV_8UC3, cv::Scalar(9, 9, 9))).markers.empty());
  }
  // A striped, a checkered and a one-colour frame.
  cv::Mat stripes(480, 640, CV_8UC1);
  for (int x = 0; x < stripes.cols; ++x) stripes.col(x).setTo((x / 3) % 2 ? 255 : 0);
  EXPECT_TRUE(detector.detect(stripes).markers.empty());
  cv::Mat checker(480, 640, CV_8UC1);
  for (int y = 0; y < checker.rows; ++y) {
    for (int x = 0; x < checker.cols; ++x)
      checker.at<std::uint8_t>(y, x) = ((x / 20 + y / 20) % 2) * 255;
  }
  EXPECT_TRUE(detector.detect(checker).markers.empty());
  EXPECT_TRUE(detector.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128))).markers.empty());
}

// A BCH marker's outline encloses its light code cells; a solid dark quadrilateral encloses none
// and is dropped before it is refined or decoded, in both searches, while a hollow one of the
// same size (a dark dot inside, as a code has dark cells) stays a candidate.
TEST(OddInput, SolidDarkSquaresAreNotCandidates) {
  cv::Mat frame(480, 640, CV_8UC1, cv::Scalar(200));
  cv::rectangle(frame, cv::Rect(100, 150, 120, 120), cv::Scalar(20), cv::FILLED);
  cv::rectangle(frame, cv::Rect(400, 150, 120, 120), cv::Scalar(20), cv::FILLED);
  cv::rectangle(frame, cv::Rect(420, 170, 80, 80), cv::Scalar(200), cv::FILLED);
  cv::rectangle(frame, cv::Rect(450, 200, 20, 20), cv::Scalar(20), cv::FILLED);  // a "code" dot
  for (int decimate : {1, 2}) {
    DetectorConfig config;
    config.search_decimate = decimate;
    MarkerDetector detector(config);
    EXPECT_TRUE(detector.detect(frame).markers.empty());
    const std::vector<SquareCorners>& squares = detector.lastSquares();
    ASSERT_EQ(squares.size(), 1u) << "decimate " << decimate;
    for (const cv::Point2f& corner : squares[0]) {
      EXPECT_GT(corner.x, 390.0f) << "decimate " << decimate;
      EXPECT_LT(corner.x, 530.0f) << "decimate " << decimate;
    }
  }
}

TEST(OddInput, AHugeFrameIsProcessed) {
  cv::Mat huge(4000, 6000, CV_8UC1, cv::Scalar(200));
  cv::rectangle(huge, cv::Rect(100, 100, 300, 300), cv::Scalar(10), cv::FILLED);
  MarkerDetector detector(DetectorConfig{});
  const DetectionResult result = detector.detect(huge);
  EXPECT_TRUE(result.markers.empty());
  EXPECT_EQ(detector.lastGrayImage().cols, 6000);
}

TEST(OddInput, RandomImagesNeverCrashOrGiveAMarker) {
  std::mt19937 random(11);
  for (MarkerKind kind : {MarkerKind::Bch, MarkerKind::Simple}) {
    DetectorConfig config;
    config.kind = kind;
    MarkerDetector detector(config);
    for (int i = 0; i < 60; ++i) {
      const int w = 8 + static_cast<int>(random() % 400), h = 8 + static_cast<int>(random() % 300);
      cv::Mat image(h, w, CV_8UC1);
      if (i % 3 == 0) {
        cv::randu(image, 0, 256);
      } else {
        image.setTo(random() % 256);
        for (int s = 0; s < 40; ++s) {
          const cv::Point a(static_cast<int>(random() % w), static_cast<int>(random() % h));
          const cv::Point b(static_cast<int>(random() % w), static_cast<int>(random() % h));
          cv::rectangle(image, a, b, cv::Scalar(static_cast<double>(random() % 256)),
                        random() % 2 ? cv::FILLED : 1 + static_cast<int>(random() % 5));
        }
      }
      EXPECT_TRUE(detector.detect(image).markers.empty()) << "image " << i;
    }
  }
}

TEST(OddInput, BadConfigurationsAreRejectedWithTheField) {
  DetectorConfig config;
  config.border = 0.5;
  EXPECT_THROW(MarkerDetector{config}, std::invalid_argument);
  config = {};
  config.threshold.value = 300;
  EXPECT_THROW(MarkerDetector{config}, std::invalid_argument);
  config = {};
  config.kind = MarkerKind::Template;
  EXPECT_THROW(MarkerDetector{config}, std::invalid_argument);
  config = {};
  config.kind = MarkerKind::Aruco;
  config.dictionary = "DICT_NONE";
  EXPECT_THROW(MarkerDetector{config}, std::invalid_argument);
  EXPECT_THROW(markerKindFromString("qr"), std::invalid_argument);
  EXPECT_THROW(thresholdModeFromString("otsu"), std::invalid_argument);
  MarkerDetector detector(DetectorConfig{});
  EXPECT_THROW(detector.detect(cv::Mat(10, 10, CV_16UC1)), std::invalid_argument);
}

}  // namespace
}  // namespace arbci::vision
