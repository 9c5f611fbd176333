// OpenCV's ArUco dictionaries, found by OpenCV's aruco module.
#include "../dictionary_detector.h"
#include "arbci/vision/marker_family.h"

namespace arbci::vision {

MarkerFamilyRegistry::Entry arucoFamily() {
  MarkerFamily family;
  family.border = 0.25;
  family.whole_image = [](const DetectorConfig& config) {
    const int dictionary =
        dictionaryId(config.dictionary.empty() ? "DICT_6X6_250" : config.dictionary);
    return WholeImageSearch{[dictionary](const cv::Mat& gray) {
                              return detectDictionaryMarkers(gray, dictionary, MarkerKind::Aruco);
                            },
                            "opencv adaptive"};
  };
  return {"aruco", "an OpenCV ArUco dictionary (detect --dictionary)", std::move(family)};
}

}  // namespace arbci::vision
