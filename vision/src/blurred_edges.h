// Private: a quad's sides placed on motion-blurred edges, for a marker that the edge
// refinement's short reach left on the outer part of a smear (see blurred_edges.cpp).
#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "quad_fit.h"

namespace arbci::vision {

// `quad` with its sides moved onto motion-blurred edges (the printed edge in the middle of a ramp
// up to 15 px wide, see blurred_edges.cpp); for a marker that refineQuad()'s short reach left on
// the smear's outer part. nullopt where a side shows no ramp or the sides no longer make a quad.
std::optional<Quad> placeOnBlurredEdges(const Quad& quad, const cv::Mat& image,
                                        const QuadFitParams& params);

}  // namespace arbci::vision
