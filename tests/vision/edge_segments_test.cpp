// The edge-segment pass (tracker.passes.edge_segments) on a hand-made frame: a finger over a
// marker's corner that reaches a dark background joins the border to the background, so no
// outline of the marker is left; the marker's straight sides still make its quad. The pass runs
// when the caller expects an id the outline search missed, or, expecting nothing in particular,
// where a marker may hide (dark components no quad came of, quads that did not decode): a frame
// whose candidates all decoded pays nothing for it.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

constexpr int kCovered = 1234, kClear = 2345;

// Two BCH markers (black squares of 96 px, a 2-cell margin) on a light table; a dark coat
// sleeve below the first, and a dark disc of a fifth of the side over that marker's bottom-left
// corner that reaches the sleeve.
cv::Mat frame() {
  cv::Mat f(480, 640, CV_8UC1, cv::Scalar(190));
  cv::rectangle(f, cv::Rect(0, 330, 300, 150), cv::Scalar(25), cv::FILLED);
  const int cell = 12;  // 8 cells a black square
  const cv::Mat covered = test::markerImage(test::MarkerFamily::ArbciBch, kCovered, cell, 2);
  const cv::Mat clear = test::markerImage(test::MarkerFamily::ArbciBch, kClear, cell, 2);
  // 12 cells a side with the margin: 144 px; the black square from 24 to 120 of it.
  test::drawWarped(f, covered, {{{80, 170}, {224, 170}, {224, 314}, {80, 314}}});
  test::drawWarped(f, clear, {{{400, 150}, {544, 150}, {544, 294}, {400, 294}}});
  cv::circle(f, cv::Point(104, 290), 19, cv::Scalar(20), cv::FILLED, cv::LINE_AA);
  cv::rectangle(f, cv::Rect(92, 290, 24, 45), cv::Scalar(20), cv::FILLED);  // the finger
  return f;
}

std::set<int> idsFound(const DetectorConfig& config) {
  MarkerDetector detector(config);
  std::set<int> ids;
  for (const MarkerDetection& m : detector.detect(frame()).markers) ids.insert(m.id);
  return ids;
}

TEST(EdgeSegments, AMarkerWhoseCoveredCornerJoinsTheBackgroundIsReadFromItsSides) {
  for (const int decimate : {1, 2}) {
    DetectorConfig config;
    config.search_decimate = decimate;
    config.passes.edge_segments.enabled = false;
    EXPECT_EQ(idsFound(config), (std::set<int>{kClear})) << "decimate " << decimate;
    config.passes.edge_segments.enabled = true;
    EXPECT_EQ(idsFound(config), (std::set<int>{kCovered, kClear})) << "decimate " << decimate;
  }
}

TEST(EdgeSegments, RunOnlyWhenAnExpectedIdIsMissing) {
  DetectorConfig config;
  config.expected_ids = {kClear};  // found by its outline: the pass does not run
  EXPECT_EQ(idsFound(config), (std::set<int>{kClear}));
  config.expected_ids = {kClear, kCovered};
  EXPECT_EQ(idsFound(config), (std::set<int>{kCovered, kClear}));
}

TEST(EdgeSegments, AFrameWhoseCandidatesAllDecodedPaysNothingForThePass) {
  cv::Mat f(480, 640, CV_8UC1, cv::Scalar(190));
  const cv::Mat clear = test::markerImage(test::MarkerFamily::ArbciBch, kClear, 12, 2);
  test::drawWarped(f, clear, {{{400, 150}, {544, 150}, {544, 294}, {400, 294}}});
  for (const int decimate : {1, 2}) {
    DetectorConfig config;
    config.search_decimate = decimate;
    MarkerDetector detector(config);
    const DetectionResult r = detector.detect(f);
    ASSERT_EQ(r.markers.size(), 1u) << "decimate " << decimate;
    EXPECT_EQ(r.timing.edges, 0.0) << "decimate " << decimate;
    // The covered marker's frame: the pass runs, and finds it.
    const DetectionResult covered = detector.detect(frame());
    EXPECT_GT(covered.timing.edges, 0.0) << "decimate " << decimate;
    EXPECT_EQ(covered.markers.size(), 2u) << "decimate " << decimate;
  }
}

}  // namespace
}  // namespace arbci::vision
