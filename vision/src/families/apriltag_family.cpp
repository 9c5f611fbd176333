// AprilTag families, found by libapriltag itself.
#include <memory>

#include "../apriltag_detector.h"
#include "arbci/vision/marker_family.h"

namespace arbci::vision {

MarkerFamilyRegistry::Entry aprilTagFamily() {
  MarkerFamily family;
  family.border = 0.25;
  family.whole_image = [](const DetectorConfig& config) {
    // Shared: the search is a copyable function, libapriltag's detector is not.
    auto detector = std::make_shared<AprilTagDetector>(
        config.dictionary, config.apriltag_refine_edges, config.search_decimate);
    return WholeImageSearch{[detector](const cv::Mat& gray) { return detector->detect(gray); },
                            "libapriltag's own"};
  };
  return {"apriltag", "an AprilTag family, found by libapriltag (detect --dictionary)",
          std::move(family)};
}

}  // namespace arbci::vision
