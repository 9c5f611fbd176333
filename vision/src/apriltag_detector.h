// Private: AprilTag markers through libapriltag itself (the families it ships), not OpenCV's
// dictionary path, which misses many tags the library finds (22 of 47 in apriltag_test).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"

namespace arbci::vision {

// The families accepted by name ("tag36h11", "tagStandard41h12", ...), for messages.
std::string aprilTagFamilies();

class AprilTagDetector {
 public:
  // `family`: a libapriltag family name, or OpenCV's DICT_APRILTAG_16h5/25h9/36h10/36h11 for
  // the same families; empty: tag36h11. `refine_edges`: each detection's sides moved onto the
  // frame's edges by ARBCI's own refinement (quad_fit's), not libapriltag's: libapriltag refines
  // before it decodes, and on a tag of a dozen pixels its refined outline no longer decodes (one
  // of its own 47 regression tags is lost). `decimate`: libapriltag's quad_decimate (1: quads found
  // at full resolution, small tags count; 2: on the frame halved, the edges then refined on the
  // frame). Throws std::invalid_argument naming the accepted ones.
  AprilTagDetector(const std::string& family, bool refine_edges, int decimate = 1);
  ~AprilTagDetector();
  AprilTagDetector(const AprilTagDetector&) = delete;
  AprilTagDetector& operator=(const AprilTagDetector&) = delete;

  // One thread. Corners as every
  // detection here: the printed tag's top-left, top-right, bottom-right, bottom-left, OpenCV
  // pixels.
  std::vector<MarkerDetection> detect(const cv::Mat& gray);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arbci::vision
