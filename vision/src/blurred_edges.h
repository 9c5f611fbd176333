// Private: a quad's sides placed on motion-blurred edges, for a marker that the edge
// refinement's short reach left on the outer part of a smear, and the test for such a smear (see
// blurred_edges.cpp).
#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "quad_fit.h"

namespace arbci::vision {

// Whether some side of `quad` is a ramp of the width motion smears a border into, as
// placeOnBlurredEdges() judges it before moving the sides (from the two middle profiles of each).
bool looksSmeared(const Quad& quad, const cv::Mat& image, const QuadFitParams& params);

// `quad` with its sides moved onto motion-blurred edges (the printed edge in the middle of a ramp
// up to 15 px wide, see blurred_edges.cpp); for a marker that refineQuad()'s short reach left on
// the smear's outer part. nullopt where a side shows no ramp or the sides no longer make a quad.
std::optional<Quad> placeOnBlurredEdges(const Quad& quad, const cv::Mat& image,
                                        const QuadFitParams& params);

}  // namespace arbci::vision
