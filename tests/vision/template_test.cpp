// Template markers (ARToolKit .patt): trained from a face-on image, recognised with the right
// orientation when tilted, saved and loaded, and an untrained pattern is rejected.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

// A square template marker, 200 px: 25 % black border, a white field with a letter and a dot in
// the top-left (so that no turn of it looks alike).
cv::Mat templateMarker(const std::string& letter) {
  cv::Mat marker(200, 200, CV_8UC1, cv::Scalar(0));
  cv::rectangle(marker, cv::Rect(50, 50, 100, 100), cv::Scalar(255), cv::FILLED);
  cv::putText(marker, letter, cv::Point(68, 135), cv::FONT_HERSHEY_SIMPLEX, 2.6, cv::Scalar(0), 9);
  cv::circle(marker, cv::Point(62, 62), 8, cv::Scalar(0), cv::FILLED);
  cv::Mat with_margin(260, 260, CV_8UC1, cv::Scalar(255));
  marker.copyTo(with_margin(cv::Rect(30, 30, 200, 200)));
  return with_margin;
}

// The marker (with margin) drawn so that its black square lands on `quad`.
void draw(cv::Mat& frame, const cv::Mat& marker, const test::Corners& quad) {
  // The black square is 200 of 260 px: extend the quad by 30/200 on each side.
  const std::vector<cv::Point2f> inner{{30, 30}, {230, 30}, {230, 230}, {30, 230}};
  const cv::Mat h =
      cv::getPerspectiveTransform(inner, std::vector<cv::Point2f>(quad.begin(), quad.end()));
  std::vector<cv::Point2f> outer{{0, 0}, {260, 0}, {260, 260}, {0, 260}}, mapped;
  cv::perspectiveTransform(outer, mapped, h);
  test::drawWarped(frame, marker, {mapped[0], mapped[1], mapped[2], mapped[3]});
}

TEST(TemplateMarkers, TrainedPatternsAreRecognisedTiltedAndTurnedWithTheirOrientation) {
  cv::Mat face_on(300, 300, CV_8UC1, cv::Scalar(200));
  draw(face_on, templateMarker("A"), {{{50, 50}, {250, 50}, {250, 250}, {50, 250}}});
  const auto a = trainTemplate(face_on, 1, 0.25);
  ASSERT_TRUE(a.has_value());
  EXPECT_LT(a->rotationalSymmetry(), 0.8f);
  cv::Mat face_on_b(300, 300, CV_8UC1, cv::Scalar(200));
  draw(face_on_b, templateMarker("K"), {{{50, 50}, {250, 50}, {250, 250}, {50, 250}}});
  const auto k = trainTemplate(face_on_b, 2, 0.25);
  ASSERT_TRUE(k.has_value());

  // A tilted "K" turned by a quarter (its printed top-left is at the image's top-right), an "A"
  // upright, and an untrained "Z".
  cv::Mat scene(480, 640, CV_8UC1, cv::Scalar(190));
  const test::Corners k_quad{{{300, 60}, {290, 190}, {160, 180}, {175, 70}}};
  draw(scene, templateMarker("K"), k_quad);
  const test::Corners a_quad{{{380, 250}, {560, 265}, {545, 430}, {370, 420}}};
  draw(scene, templateMarker("A"), a_quad);
  draw(scene, templateMarker("Z"), {{{40, 260}, {200, 260}, {200, 420}, {40, 420}}});

  DetectorConfig config;
  config.kind = MarkerKind::Template;
  config.border = 0.25;
  config.templates = {*a, *k};
  MarkerDetector detector(config);
  const auto markers = detector.detect(scene).markers;
  ASSERT_EQ(markers.size(), 2u) << "the untrained pattern must be rejected";
  for (const MarkerDetection& m : markers) {
    const test::Corners& truth = m.id == 1 ? a_quad : k_quad;
    ASSERT_TRUE(m.id == 1 || m.id == 2);
    EXPECT_GT(m.confidence, 0.8f);
    for (int c = 0; c < 4; ++c)
      EXPECT_LT(cv::norm(m.corners[c] - truth[c]), 1.0) << "id " << m.id << " corner " << c;
  }
}

TEST(TemplateMarkers, PattFilesRoundTripAndBadFilesNameTheProblem) {
  cv::Mat face_on(300, 300, CV_8UC1, cv::Scalar(200));
  draw(face_on, templateMarker("R"), {{{50, 50}, {250, 50}, {250, 250}, {50, 250}}});
  const auto pattern = trainTemplate(face_on, 5, 0.25);
  ASSERT_TRUE(pattern.has_value());
  const auto path = std::filesystem::temp_directory_path() / "arbci_template_test.patt";
  pattern->save(path);
  const TemplatePattern loaded = TemplatePattern::load(path, 5);
  for (int t = 0; t < 4; ++t) {
    for (size_t i = 0; i < loaded.rotations[t].size(); ++i) {
      EXPECT_NEAR(loaded.rotations[t][i], pattern->rotations[t][i], 0.51f);
    }
  }
  std::ofstream(path) << "12 34 56\n";
  try {
    TemplatePattern::load(path, 1);
    FAIL() << "a truncated pattern file was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos);
  }
  EXPECT_THROW(TemplatePattern::load("/nonexistent.patt", 1), std::runtime_error);
}

}  // namespace
}  // namespace arbci::vision
