#include "dictionary_detector.h"

#include <opencv2/aruco.hpp>
#include <stdexcept>
#include <utility>

#include "arbci/vision/marker_detector.h"

namespace arbci::vision {
namespace {

const std::vector<std::pair<std::string, int>>& dictionaries() {
  using namespace cv::aruco;
  static const std::vector<std::pair<std::string, int>> names{
      {"DICT_4X4_50", DICT_4X4_50},
      {"DICT_4X4_100", DICT_4X4_100},
      {"DICT_4X4_250", DICT_4X4_250},
      {"DICT_4X4_1000", DICT_4X4_1000},
      {"DICT_5X5_50", DICT_5X5_50},
      {"DICT_5X5_100", DICT_5X5_100},
      {"DICT_5X5_250", DICT_5X5_250},
      {"DICT_5X5_1000", DICT_5X5_1000},
      {"DICT_6X6_50", DICT_6X6_50},
      {"DICT_6X6_100", DICT_6X6_100},
      {"DICT_6X6_250", DICT_6X6_250},
      {"DICT_6X6_1000", DICT_6X6_1000},
      {"DICT_7X7_50", DICT_7X7_50},
      {"DICT_7X7_100", DICT_7X7_100},
      {"DICT_7X7_250", DICT_7X7_250},
      {"DICT_7X7_1000", DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", DICT_APRILTAG_36h11}};
  return names;
}

}  // namespace

std::vector<std::string> dictionaryNames() {
  std::vector<std::string> names;
  for (const auto& [name, id] : dictionaries()) names.push_back(name);
  return names;
}

int dictionaryId(const std::string& name) {
  for (const auto& [known, id] : dictionaries()) {
    if (known == name) return id;
  }
  throw std::invalid_argument("unknown dictionary '" + name +
                              "' (e.g. DICT_6X6_250, DICT_APRILTAG_36h11)");
}

std::vector<MarkerDetection> detectDictionaryMarkers(const cv::Mat& gray, int dictionary,
                                                     MarkerKind kind) {
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(dictionary);
  const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dict, corners, ids, params);
  std::vector<MarkerDetection> markers;
  for (size_t i = 0; i < ids.size(); ++i) {
    MarkerDetection marker;
    marker.id = ids[i];
    marker.kind = kind;
    // OpenCV gives the marker's corners clockwise from its top-left.
    for (int k = 0; k < 4; ++k) marker.corners[k] = corners[i][k];
    marker.confidence = 1.0f;
    markers.push_back(marker);
  }
  return markers;
}

}  // namespace arbci::vision
