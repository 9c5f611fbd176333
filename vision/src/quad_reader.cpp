#include "quad_reader.h"

#include "arbci/vision/marker_family.h"
#include "blurred_edges.h"
#include "code_decoder.h"

namespace arbci::vision {
namespace {

// Samples with contrast and a dark border all round: a marker if its code decodes. A quad fitted
// around a covered corner may show light there: a finger over a corner, a quarter of a side
// across, hides an eighth of the border samples (two sides' quarter each).
bool hasMarkerBorder(const MarkerSamples& samples, bool occluded = false) {
  const int light_allowed =
      samples.border_samples / 10 + (occluded ? samples.border_samples / 8 : 0);
  return samples.contrast >= 8.0f && samples.border_light <= light_allowed;
}

}  // namespace

std::optional<MarkerDetection> readQuad(const DetectorConfig& config, const MarkerFamily& family,
                                        const cv::Mat& image, const Quad& quad,
                                        const MarkerSamples& samples, bool chase) {
  if (!hasMarkerBorder(samples, quad.occluded)) return std::nullopt;
  MarkerDetection marker;
  marker.kind = config.kind;
  if (family.templates) {
    const auto match =
        matchTemplate(sampleCodeArea(image, quad, config.border, TemplatePattern::kSize),
                      config.templates, config.template_limits);
    if (!match) return std::nullopt;
    marker.id = match->id;
    marker.orientation = match->orientation;
    marker.confidence = match->confidence;
  } else {
    const CodeReadings readings = !config.soft_decoding ? CodeReadings::Plain
                                  : chase               ? CodeReadings::SharpenedAndChase
                                                        : CodeReadings::Sharpened;
    const auto code = decodeCode(*family.code, samples, readings);
    if (!code) return std::nullopt;
    marker.id = code->id;
    marker.orientation = code->orientation;
    marker.confidence = code->confidence;
    marker.corrected_bits = code->corrected_bits;
  }
  // Printed corner k (TL, TR, BR, BL) is quad corner (k + 4 - orientation) mod 4.
  for (int k = 0; k < 4; ++k) {
    marker.corners[k] = quad.corners[(k + 4 - marker.orientation) % 4];
    marker.ideal_corners[k] = quad.ideal_corners[(k + 4 - marker.orientation) % 4];
  }
  return marker;
}

// Chase decoding is left out of the second reading: on motion-blurred frames it read more
// markers, but also decoys of marker-free frames as markers (a second reading of every failing
// decoy doubles its chances). A quad that failed for want of contrast or a dark border is not
// moved: none such read after the move.
std::optional<MarkerDetection> readOnBlurredEdges(const DetectorConfig& config,
                                                  const MarkerFamily& family, const cv::Mat& gray,
                                                  Quad& quad, MarkerSamples& samples) {
  if (!config.passes.blurred_edges.enabled || !hasMarkerBorder(samples)) return std::nullopt;
  QuadFitParams params;
  params.min_side = config.min_side_px;
  params.lens = config.lens.get();
  const auto placed = placeOnBlurredEdges(quad, gray, params);
  if (!placed) return std::nullopt;
  // Sides that hardly moved read as before.
  float moved = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f d = placed->corners[k] - quad.corners[k];
    moved = std::max(moved, d.dot(d));
  }
  const float least = static_cast<float>(config.passes.blurred_edges.min_move_px);
  if (moved < least * least) return std::nullopt;
  MarkerSamples placed_samples = sampleMarker(gray, *placed, config.border);
  auto marker = readQuad(config, family, gray, *placed, placed_samples, /*chase=*/false);
  if (marker) {
    quad = *placed;
    samples = placed_samples;
  }
  return marker;
}

}  // namespace arbci::vision
