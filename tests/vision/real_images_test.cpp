// The tracker on real photographs with known markers (../shared/data/vision, SOURCES.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

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

// AprilTag through libapriltag: every tag of the library's own regression images, at its
// reference corners (libapriltag's pixel centres sit +0.5 from OpenCV's). The references were
// made without edge refinement: off, each corner lies within a pixel of its reference; with it
// (the default, ARBCI's refinement after decoding) the corners move onto the edges, by a third
// of a pixel typically and up to 3.5 px on the most oblique tags (libapriltag's own refinement
// moves those 2.4 px), and no tag may be lost (libapriltag's refinement before decoding lost the
// 12-pixel tag near (702, 114)).
void expectEveryReferenceTag(bool refine_edges, float tolerance_px) {
  DetectorConfig config;
  config.kind = MarkerKind::AprilTag;
  config.apriltag_refine_edges = refine_edges;
  MarkerDetector detector(config);
  int reference_tags = 0, found_tags = 0;
  for (const char* name :
       {"33369213973_9d9bb4cc96_c", "34085369442_304b6bafd9_c", "34139872896_defdb2f8d9_c"}) {
    const std::string base = test::sharedData(std::string("vision/apriltag_test/") + name);
    std::ifstream in(base + ".txt");
    ASSERT_TRUE(in) << base;
    std::vector<std::array<cv::Point2f, 4>> reference;
    std::string line;
    while (std::getline(in, line)) {
      std::array<float, 8> v{};
      int id = -1;
      if (std::sscanf(line.c_str(), "%d, (%f %f), (%f %f), (%f %f), (%f %f)", &id, &v[0], &v[1],
                      &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]) != 9)
        continue;
      std::array<cv::Point2f, 4> corners;
      for (int k = 0; k < 4; ++k) corners[k] = {v[2 * k] - 0.5f, v[2 * k + 1] - 0.5f};
      reference.push_back(corners);
    }
    reference_tags += static_cast<int>(reference.size());
    const DetectionResult result = detector.detect(cv::imread(base + ".jpg"));
    // The frame is thresholded by libapriltag, not by OpenCV's dictionary path.
    EXPECT_EQ(result.threshold_mode, "libapriltag's own") << name;
    const auto& markers = result.markers;
    EXPECT_EQ(markers.size(), reference.size()) << name;
    for (const auto& m : markers) {
      EXPECT_EQ(m.id, 0) << name;
      EXPECT_EQ(m.kind, MarkerKind::AprilTag);
    }
    // Each reference tag has a detection whose corners (libapriltag's p[3], p[2], p[1], p[0] as
    // top-left, top-right, bottom-right, bottom-left) lie within the tolerance of it.
    for (const auto& ref : reference) {
      const bool found = std::any_of(markers.begin(), markers.end(), [&](const auto& m) {
        for (int k = 0; k < 4; ++k)
          if (cv::norm(m.corners[k] - ref[3 - k]) > tolerance_px) return false;
        return true;
      });
      found_tags += found;
      EXPECT_TRUE(found) << name << ": the reference tag at " << ref[0] << " was lost";
    }
  }
  EXPECT_EQ(reference_tags, 47);
  EXPECT_EQ(found_tags, 47);
}

TEST(AprilTags, EveryReferenceTagOfTheLibrarysTestImagesAtItsCorners) {
  expectEveryReferenceTag(false, 1.0f);
}

TEST(AprilTags, EveryReferenceTagWithEdgeRefinementTheDefault) {
  expectEveryReferenceTag(true, 4.0f);
}

// OpenCV's AprilTag dictionary names choose the same family. OpenCV's aruco module reads these
// tags rotated 180 degrees (its first corner is the printed bottom-right; ours the top-left, as
// libapriltag's canonical image shows): each of its corners is nearest our opposite one.
TEST(AprilTags, OpenCvDictionaryNamesChooseTheSameFamilyAndUnknownOnesAreRefused) {
  DetectorConfig config;
  config.kind = MarkerKind::AprilTag;
  config.dictionary = "DICT_APRILTAG_36h11";
  MarkerDetector detector(config);
  const auto markers =
      detector
          .detect(cv::imread(test::sharedData("vision/apriltag_test/33369213973_9d9bb4cc96_c.jpg")))
          .markers;
  EXPECT_EQ(markers.size(), 12u);
  DetectorConfig opencv;
  opencv.kind = MarkerKind::Aruco;
  opencv.dictionary = "DICT_APRILTAG_36h11";
  const auto theirs =
      MarkerDetector(opencv)
          .detect(cv::imread(test::sharedData("vision/apriltag_test/33369213973_9d9bb4cc96_c.jpg")))
          .markers;
  ASSERT_GE(theirs.size(), 10u);
  // OpenCV's corners are a few pixels off on these blurred photos: what must agree is the order,
  // each of its corners nearest the same corner of ours.
  auto centre = [](const auto& q) { return 0.25f * (q[0] + q[1] + q[2] + q[3]); };
  int compared = 0;
  for (const auto& t : theirs) {
    const auto ours =
        std::min_element(markers.begin(), markers.end(), [&](const auto& a, const auto& b) {
          return cv::norm(centre(a.corners) - centre(t.corners)) <
                 cv::norm(centre(b.corners) - centre(t.corners));
        });
    // One of OpenCV's is in neither libapriltag's detections nor the reference.
    if (cv::norm(centre(ours->corners) - centre(t.corners)) > 6.0) continue;
    ++compared;
    for (int k = 0; k < 4; ++k) {
      int nearest = 0;
      for (int j = 1; j < 4; ++j) {
        if (cv::norm(ours->corners[j] - t.corners[k]) <
            cv::norm(ours->corners[nearest] - t.corners[k]))
          nearest = j;
      }
      EXPECT_EQ(nearest, (k + 2) % 4) << "OpenCV's tag with first corner " << t.corners[0];
    }
  }
  EXPECT_GE(compared, 10);
  config.dictionary = "tag99h99";
  try {
    MarkerDetector refused(config);
    FAIL() << "an unknown family was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("tagStandard41h12"), std::string::npos)
        << error.what();
  }
}

// A frame with JPEG's 8 px block edges (an MJPEG camera) is smoothed before the full-resolution
// search; an uncompressed or finely compressed one is not. Block-edge ratios (steps across the
// grid over steps beside it): the webcam frame 1.39, the photo 1.05, the photo at quality 50 1.30.
TEST(JpegFrames, AreSmoothedWhenTheirBlockEdgesShow) {
  auto smoothed = [](const cv::Mat& frame) {
    MarkerDetector detector(DetectorConfig{});
    return detector.detect(frame).threshold_mode.find("smoothed") != std::string::npos;
  };
  const cv::Mat webcam = cv::imread(test::sharedData("vision/opencv_samples_chessboard/left01.jpg"),
                                    cv::IMREAD_GRAYSCALE);
  const cv::Mat photo = cv::imread(
      test::sharedData("vision/apriltag_test/33369213973_9d9bb4cc96_c.jpg"), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(webcam.empty());
  ASSERT_FALSE(photo.empty());
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", photo, jpeg, {cv::IMWRITE_JPEG_QUALITY, 50});
  const cv::Mat photo_q50 = cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
  EXPECT_TRUE(smoothed(webcam));
  EXPECT_FALSE(smoothed(photo));
  EXPECT_TRUE(smoothed(photo_q50));
  // The same frame searched at half resolution is averaged over 2x2 pixels instead.
  DetectorConfig decimated;
  decimated.search_decimate = 2;
  MarkerDetector detector(decimated);
  EXPECT_EQ(detector.detect(webcam).threshold_mode.find("smoothed"), std::string::npos);
}

}  // namespace
}  // namespace arbci::vision
