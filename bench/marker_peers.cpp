#include "marker_peers.h"

#include <apriltag.h>
#include <tag36h11.h>

#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"

namespace arbci::bench {
namespace {

class ArbciTracker final : public MarkerDetectorUnderTest {
 public:
  ArbciTracker(int decimate, const vision::SearchPasses& passes)
      : decimate_(decimate), detector_(config(decimate, passes)) {}
  std::string name() const override {
    return decimate_ == 1 ? "ARBCI (BCH, adaptive)"
                          : "ARBCI (BCH, decimate " + std::to_string(decimate_) + ")";
  }
  test::MarkerFamily family() const override { return test::MarkerFamily::ArbciBch; }
  bool orderedCorners() const override { return true; }
  std::vector<test::FoundMarker> detect(const cv::Mat& gray) override {
    const vision::DetectionResult result = detector_.detect(gray);
    stages_ = result.timing;
    std::vector<test::FoundMarker> found;
    for (const vision::MarkerDetection& m : result.markers) found.push_back({m.id, m.corners});
    return found;
  }
  std::optional<vision::StageTimes> lastStageTimes() const override { return stages_; }
  std::optional<Miss> explainMiss(const cv::Mat& gray, const test::Corners& truth,
                                  int id) override {
    Miss miss;
    const std::vector<cv::Point2f> outline(truth.begin(), truth.end());
    const double area = cv::contourArea(outline);
    for (const vision::SquareCorners& square : detector_.lastSquares()) {
      const std::vector<cv::Point2f> corners(square.begin(), square.end());
      const cv::Point2f centre = (square[0] + square[1] + square[2] + square[3]) * 0.25f;
      const double square_area = cv::contourArea(corners);
      if (cv::pointPolygonTest(outline, centre, false) > 0 && square_area > 0.5 * area &&
          square_area < 2.0 * area)
        miss.square_on_it = true;
    }
    const auto read = detector_.readAt(gray, truth);
    miss.readable_at_truth = read && read->id == id;
    return miss;
  }

 private:
  static vision::DetectorConfig config(int decimate, const vision::SearchPasses& passes) {
    vision::DetectorConfig c;
    c.search_decimate = decimate;
    c.passes = passes;
    c.kind = vision::MarkerKind::Bch;
    c.border = 0.125;
    c.threshold.mode = vision::ThresholdMode::Adaptive;
    return c;
  }
  int decimate_;
  vision::MarkerDetector detector_;
  vision::StageTimes stages_;
};

class AprilTag final : public MarkerDetectorUnderTest {
 public:
  explicit AprilTag(float decimate) : decimate_(decimate) {
    family_ = tag36h11_create();
    detector_ = apriltag_detector_create();
    apriltag_detector_add_family(detector_, family_);
    detector_->quad_decimate = decimate;
  }
  ~AprilTag() override {
    apriltag_detector_destroy(detector_);
    tag36h11_destroy(family_);
  }
  std::string name() const override {
    return "AprilTag 3 (36h11, decimate " + std::to_string(static_cast<int>(decimate_)) + ")";
  }
  test::MarkerFamily family() const override { return test::MarkerFamily::AprilTag36h11; }
  bool orderedCorners() const override { return false; }
  std::vector<test::FoundMarker> detect(const cv::Mat& gray) override {
    image_u8_t image{gray.cols, gray.rows, static_cast<int32_t>(gray.step), gray.data};
    zarray_t* detections = apriltag_detector_detect(detector_, &image);
    std::vector<test::FoundMarker> found;
    for (int i = 0; i < zarray_size(detections); ++i) {
      apriltag_detection_t* d = nullptr;
      zarray_get(detections, i, &d);
      test::FoundMarker m;
      m.id = d->id;
      // libapriltag's pixel centres are at +0.5 of OpenCV's.
      for (int k = 0; k < 4; ++k) {
        m.corners[k] =
            cv::Point2f(static_cast<float>(d->p[k][0] - 0.5), static_cast<float>(d->p[k][1] - 0.5));
      }
      found.push_back(m);
    }
    apriltag_detections_destroy(detections);
    return found;
  }

 private:
  float decimate_;
  apriltag_family_t* family_;
  apriltag_detector_t* detector_;
};

class Aruco final : public MarkerDetectorUnderTest {
 public:
  Aruco()
      : dictionary_(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_6X6_250)),
        parameters_(cv::aruco::DetectorParameters::create()) {}
  std::string name() const override { return "OpenCV ArUco (6x6_250)"; }
  test::MarkerFamily family() const override { return test::MarkerFamily::Aruco6x6; }
  bool orderedCorners() const override { return true; }
  std::vector<test::FoundMarker> detect(const cv::Mat& gray) override {
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(gray, dictionary_, corners, ids, parameters_);
    std::vector<test::FoundMarker> found;
    for (size_t i = 0; i < ids.size(); ++i) {
      test::FoundMarker m;
      m.id = ids[i];
      for (int k = 0; k < 4; ++k) m.corners[k] = corners[i][k];
      found.push_back(m);
    }
    return found;
  }

 private:
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
};

}  // namespace

std::unique_ptr<MarkerDetectorUnderTest> makeArbciTracker(int decimate,
                                                          const vision::SearchPasses& passes) {
  return std::make_unique<ArbciTracker>(decimate, passes);
}
std::unique_ptr<MarkerDetectorUnderTest> makeAprilTag(float decimate) {
  return std::make_unique<AprilTag>(decimate);
}
std::unique_ptr<MarkerDetectorUnderTest> makeAruco() {
  return std::make_unique<Aruco>();
}

std::vector<std::unique_ptr<MarkerDetectorUnderTest>> detectorsUnderTest(
    const vision::SearchPasses& passes, bool peers) {
  std::vector<std::unique_ptr<MarkerDetectorUnderTest>> detectors;
  detectors.push_back(makeArbciTracker(1, passes));
  detectors.push_back(makeArbciTracker(2, passes));
  if (peers) {
    detectors.push_back(makeAprilTag(2.0f));
    detectors.push_back(makeAprilTag(1.0f));
    detectors.push_back(makeAruco());
  }
  return detectors;
}

}  // namespace arbci::bench
