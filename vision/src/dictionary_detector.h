// Private: ArUco and AprilTag markers through OpenCV's aruco module.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"

namespace arbci::vision {

// Throws std::invalid_argument for an unknown dictionary name.
int dictionaryId(const std::string& name);

std::vector<MarkerDetection> detectDictionaryMarkers(const cv::Mat& gray, int dictionary,
                                                     MarkerKind kind);

}  // namespace arbci::vision
