// The JSON form of a frame's detections, as `arbci detect` prints it and the session logs it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "arbci/vision/marker.h"

namespace arbci::app {

nlohmann::json markerJson(const vision::MarkerDetection& marker);
nlohmann::json stageTimesJson(const vision::StageTimes& times);

}  // namespace arbci::app
