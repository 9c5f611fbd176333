// OpenCV's ArUco dictionaries, found by OpenCV's aruco module.
#include "../dictionary_detector.h"
#include "arbci/vision/marker_family.h"

namespace arbci::vision {
namespace {

class ArucoSearch : public WholeImageSearch {
 public:
  explicit ArucoSearch(const std::string& dictionary)
      : dictionary_(dictionaryId(dictionary.empty() ? "DICT_6X6_250" : dictionary)) {}
  std::vector<MarkerDetection> detect(const cv::Mat& gray) override {
    return detectDictionaryMarkers(gray, dictionary_, MarkerKind::Aruco);
  }
  std::string thresholdMode() const override { return "opencv adaptive"; }

 private:
  int dictionary_;
};

}  // namespace

MarkerFamilyRegistry::Entry arucoFamily() {
  MarkerFamily family;
  family.border = 0.25;
  family.whole_image = [](const DetectorConfig& config) {
    return std::make_unique<ArucoSearch>(config.dictionary);
  };
  return {"aruco", "an OpenCV ArUco dictionary (detect --dictionary)", family};
}

}  // namespace arbci::vision
