#include "support/detection_json.h"

#include <cmath>

namespace arbci::app {
namespace {
// Rounded to 1 / scale (scale 1000: three decimals) so that JSON prints short numbers.
double rounded(double value, double scale) {
  return std::round(value * scale) / scale;
}
}  // namespace

nlohmann::json markerJson(const vision::MarkerDetection& marker) {
  nlohmann::json corners = nlohmann::json::array();
  for (const cv::Point2f& p : marker.corners)
    corners.push_back({rounded(p.x, 1000), rounded(p.y, 1000)});
  nlohmann::json out{{"id", marker.id},
                     {"kind", vision::toString(marker.kind)},
                     {"corners", corners},
                     {"confidence", rounded(marker.confidence, 1000)},
                     {"orientation", marker.orientation}};
  if (marker.corrected_bits > 0) out["corrected_bits"] = marker.corrected_bits;
  if (marker.from_history) out["from_history"] = true;
  return out;
}

nlohmann::json stageTimesJson(const vision::StageTimes& t) {
  auto us = [](double value) { return rounded(value, 10); };
  nlohmann::json out = {{"total", us(t.total)}};
  for (const auto& [name, part] : vision::kStageParts) out[name] = us(t.*part);
  return out;
}

}  // namespace arbci::app
