#include <algorithm>

#include "arbci/vision/marker_detector.h"
#include "marker_sampler.h"

namespace arbci::vision {

std::optional<TemplatePattern> trainTemplate(const cv::Mat& image, int id, double border) {
  DetectorConfig config;
  config.kind = MarkerKind::Bch;  // any square kind: only the outlines are used
  config.border = border;
  MarkerDetector detector(config);
  detector.detect(image);
  // The largest square with a black border all round (not, say, the white card it is printed on).
  std::vector<SquareCorners> squares;
  for (const SquareCorners& corners : detector.lastSquares()) {
    Quad quad;
    quad.corners = corners;
    const MarkerSamples samples = sampleMarker(detector.lastGrayImage(), quad, border);
    if (samples.contrast >= 8.0f && samples.border_light * 10 <= samples.border_samples)
      squares.push_back(corners);
  }
  if (squares.empty()) return std::nullopt;
  auto area = [](const SquareCorners& q) {
    float a = 0.0f;
    for (int k = 0; k < 4; ++k) a += q[k].x * q[(k + 1) % 4].y - q[(k + 1) % 4].x * q[k].y;
    return std::abs(a);
  };
  const SquareCorners& largest =
      *std::max_element(squares.begin(), squares.end(),
                        [&](const auto& a, const auto& b) { return area(a) < area(b); });
  // Upright: the corner nearest the image's top-left is the pattern's top-left.
  int top_left = 0;
  for (int k = 1; k < 4; ++k) {
    if (largest[k].x + largest[k].y < largest[top_left].x + largest[top_left].y) top_left = k;
  }
  Quad quad;
  for (int k = 0; k < 4; ++k) quad.corners[k] = largest[(top_left + k) % 4];
  return TemplatePattern::fromUpright(
      id, "pattern " + std::to_string(id),
      sampleCodeArea(detector.lastGrayImage(), quad, border, TemplatePattern::kSize));
}

}  // namespace arbci::vision
