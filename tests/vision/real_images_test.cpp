// The tracker on real photographs with known markers (../shared/data/vision, SOURCES.md).
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "arbci/vision/marker_detector.h"
#include "support/shared_data.h"

namespace arbci::vision {
namespace {

cv::Mat readRaw320x240(const std::string& name) {
  std::ifstream in(test::sharedData("vision/artoolkitplus_samples/" + name), std::ios::binary);
  cv::Mat image(240, 320, CV_8UC1);
  in.read(reinterpret_cast<char*>(image.data), 320 * 240);
  EXPECT_TRUE(in.good()) << name;
  return image;
}

struct Sample {
  const char* file;
  MarkerKind kind;
  double border;
  int id;
  std::array<cv::Point2f, 4> raw_corners;  // ARToolKitPlus, full-res labelling, no undistortion
};

const Sample kSamples[] = {
    {"image_320_240_8_marker_id_simple_nr031.raw",
     MarkerKind::Simple,
     0.25,
     31,
     {{{215.88f, 148.37f}, {270.19f, 191.04f}, {186.36f, 221.63f}, {140.47f, 170.88f}}}},
    {"image_320_240_8_marker_id_simple_nr321.raw",
     MarkerKind::Simple,
     0.25,
     321,
     {{{256.90f, 139.29f}, {119.15f, 180.10f}, {74.37f, 106.46f}, {185.64f, 83.17f}}}},
    {"image_320_240_8_marker_id_bch_nr0100.raw",
     MarkerKind::Bch,
     0.125,
     100,
     {{{199.11f, 69.71f}, {246.15f, 135.11f}, {117.34f, 164.14f}, {92.95f, 89.48f}}}},
};

class ArToolKitPlusSamples : public testing::TestWithParam<ThresholdMode> {};

TEST_P(ArToolKitPlusSamples, GiveTheirIdsWithCornersWithinAPixelOfArToolKitPlus) {
  for (const Sample& sample : kSamples) {
    DetectorConfig config;
    config.kind = sample.kind;
    config.border = sample.border;
    config.threshold.mode = GetParam();
    config.threshold.value = 150;  // the sample programs' threshold
    MarkerDetector detector(config);
    const DetectionResult result = detector.detect(readRaw320x240(sample.file));
    ASSERT_EQ(result.markers.size(), 1u) << sample.file;
    const MarkerDetection& m = result.markers[0];
    EXPECT_EQ(m.id, sample.id) << sample.file;
    EXPECT_EQ(m.confidence, 1.0f) << sample.file;
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT(cv::norm(m.corners[k] - sample.raw_corners[k]), 1.0)
          << sample.file << " corner " << k << " at " << m.corners[k] << ", ARToolKitPlus "
          << sample.raw_corners[k];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ThresholdModes, ArToolKitPlusSamples,
                         testing::Values(ThresholdMode::Constant, ThresholdMode::Adaptive,
                                         ThresholdMode::AutoMidrange, ThresholdMode::AutoMedian),
                         [](const auto& info) {
                           std::string name = toString(info.param);
                           std::erase(name, '-');
                           return name;
                         });

TEST(ArToolKitPlusMarkerBoard, FindsAtLeastTheTenMarkersArToolKitPlusFinds) {
  for (ThresholdMode mode : {ThresholdMode::Constant, ThresholdMode::Adaptive}) {
    DetectorConfig config;
    config.kind = MarkerKind::Simple;
    config.border = 0.125;
    config.threshold.mode = mode;
    config.threshold.value = 160;
    MarkerDetector detector(config);
    const DetectionResult result = detector.detect(readRaw320x240("markerboard_480-499.raw"));
    std::set<int> ids;
    for (const MarkerDetection& m : result.markers) {
      EXPECT_GE(m.id, 480) << toString(mode);
      EXPECT_LE(m.id, 499) << toString(mode);
      ids.insert(m.id);
    }
    EXPECT_EQ(ids.size(), result.markers.size()) << "an id reported twice";
    // ARToolKitPlus with its candidate cap raised finds 486-489, 491-493, 496-498.
    for (int id : {486, 487, 488, 489, 491, 492, 493, 496, 497, 498}) {
      EXPECT_TRUE(ids.count(id)) << "missing " << id << " with " << toString(mode);
    }
    EXPECT_GE(ids.size(), 10u) << toString(mode);
  }
}

TEST(OpenCvDictionaries, ArucoTutorialPhotosGiveTheirIds) {
  DetectorConfig config;
  config.kind = MarkerKind::Aruco;
  MarkerDetector detector(config);
  std::set<int> ids;
  for (const auto& m : detector
                           .detect(cv::imread(test::sharedData(
                               "vision/opencv_contrib_aruco_tutorial/singlemarkersoriginal.jpg")))
                           .markers) {
    ids.insert(m.id);
  }
  EXPECT_EQ(ids, (std::set<int>{23, 40, 62, 98, 124, 203}));
  ids.clear();
  for (const auto& m : detector
                           .detect(cv::imread(test::sharedData(
                               "vision/opencv_contrib_aruco_tutorial/choriginal.jpg")))
                           .markers) {
    ids.insert(m.id);
  }
  std::set<int> board;
  for (int id = 0; id <= 16; ++id) board.insert(id);
  EXPECT_EQ(ids, board);
}

TEST(OpenCvDictionaries, AprilTagPhotosGiveTagZeroAsOftenAsOpenCvFindsIt) {
  DetectorConfig config;
  config.kind = MarkerKind::AprilTag;
  MarkerDetector detector(config);
  // OpenCV 4.6's count per photo (SOURCES.md); every detection must be id 0.
  const std::pair<const char*, size_t> photos[] = {{"33369213973_9d9bb4cc96_c.jpg", 11},
                                                   {"34085369442_304b6bafd9_c.jpg", 4},
                                                   {"34139872896_defdb2f8d9_c.jpg", 7}};
  for (const auto& [file, count] : photos) {
    const auto markers =
        detector.detect(cv::imread(test::sharedData(std::string("vision/apriltag_test/") + file)))
            .markers;
    EXPECT_GE(markers.size(), count) << file;
    for (const auto& m : markers) EXPECT_EQ(m.id, 0) << file;
  }
}

}  // namespace
}  // namespace arbci::vision
