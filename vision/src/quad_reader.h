// Private: reading a quad the search found as a marker of the configured square kind (BCH, simple
// or template): its samples must show contrast and a dark border all round, then its code must
// decode. A quad whose code does not read may be read again on its motion-blurred edges
// (passes.blurred_edges).
#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_family.h"
#include "marker_sampler.h"
#include "quad_fit.h"

namespace arbci::vision {

// The marker of `family` (config.kind's, resolved once by the detector) that `quad`'s `samples`
// of `image` read as, its corners in the printed order; without `chase`, BCH codes are not
// Chase-decoded.
std::optional<MarkerDetection> readQuad(const DetectorConfig& config, const MarkerFamily& family,
                                        const cv::Mat& image, const Quad& quad,
                                        const MarkerSamples& samples, bool chase = true);

// A quad with a marker's border whose code does not decode, its sides moved onto motion-blurred
// edges and read again, without Chase decoding; then `quad` and `samples` are the moved quad's.
std::optional<MarkerDetection> readOnBlurredEdges(const DetectorConfig& config,
                                                  const MarkerFamily& family, const cv::Mat& gray,
                                                  Quad& quad, MarkerSamples& samples);

}  // namespace arbci::vision
