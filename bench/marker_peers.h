// The peers the tracker is measured against, behind one interface: libapriltag 3 (tag36h11) and
// OpenCV 4.6's ArUco (DICT_6X6_250), each at its library's default settings.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"
#include "arbci/vision/search_passes.h"
#include "support/marker_scoring.h"

namespace arbci::bench {

class MarkerDetectorUnderTest {
 public:
  virtual ~MarkerDetectorUnderTest() = default;
  virtual std::string name() const = 0;
  virtual test::MarkerFamily family() const = 0;
  virtual bool orderedCorners() const = 0;
  virtual std::vector<test::FoundMarker> detect(const cv::Mat& gray) = 0;
  // The last frame's time per stage, for detectors that measure it (ARBCI's own).
  virtual std::optional<vision::StageTimes> lastStageTimes() const { return std::nullopt; }
  // A marker the last frame's detection missed, as the detectors that can tell (ARBCI's own) see
  // it: whether that frame gave a square on it (its centre inside the true outline, half to
  // twice its area), and whether it reads as its id at its true corners.
  struct Miss {
    bool square_on_it = false;
    bool readable_at_truth = false;
  };
  virtual std::optional<Miss> explainMiss(const cv::Mat& /*gray*/, const test::Corners& /*truth*/,
                                          int /*id*/) {
    return std::nullopt;
  }
};

// decimate: the tracker's search_decimate (1: full resolution); passes: its search's passes.
std::unique_ptr<MarkerDetectorUnderTest> makeArbciTracker(int decimate,
                                                          const vision::SearchPasses& passes = {});
std::unique_ptr<MarkerDetectorUnderTest> makeAprilTag(float decimate);
std::unique_ptr<MarkerDetectorUnderTest> makeAruco();
// ARBCI's full and decimated searches (with `passes`), then, with `peers`, libapriltag (decimate 2
// and 1) and ArUco: the detectors every marker bench compares.
std::vector<std::unique_ptr<MarkerDetectorUnderTest>> detectorsUnderTest(
    const vision::SearchPasses& passes = {}, bool peers = true);

}  // namespace arbci::bench
