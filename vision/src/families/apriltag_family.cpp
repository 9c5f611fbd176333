// AprilTag families, found by libapriltag itself.
#include "../apriltag_detector.h"
#include "arbci/vision/marker_family.h"

namespace arbci::vision {
namespace {

class AprilTagSearch : public WholeImageSearch {
 public:
  explicit AprilTagSearch(const DetectorConfig& config)
      : detector_(config.dictionary, config.apriltag_refine_edges, config.search_decimate) {}
  std::vector<MarkerDetection> detect(const cv::Mat& gray) override {
    return detector_.detect(gray);
  }
  std::string thresholdMode() const override { return "libapriltag's own"; }

 private:
  AprilTagDetector detector_;
};

}  // namespace

MarkerFamilyRegistry::Entry aprilTagFamily() {
  MarkerFamily family;
  family.border = 0.25;
  family.whole_image = [](const DetectorConfig& config) {
    return std::make_unique<AprilTagSearch>(config);
  };
  return {"apriltag", "an AprilTag family, found by libapriltag (detect --dictionary)", family};
}

}  // namespace arbci::vision
