// Private: quadrilaterals assembled from straight edge segments rather than from a component's
// outline. A finger over a marker's corner that also touches the background joins the border's
// dark component to the background's, so no outline of the marker exists to fit; the marker's
// sides are still straight edges, dark on the inside. Segments come from OpenCV's line segment
// detector (LSD) on a half-resolution image; each is oriented with its dark side on its right;
// four that follow one another turning right, end near the next one's start (one gap may be as
// long as a covered corner) and cover most of their sides make a quad, its corners the lines'
// intersections. As AprilTag 3 fits its quads to edge points rather than to outlines.
#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

#include "quad_fit.h"

namespace arbci::vision {

// As tracker.passes.edge_segments (search_passes.h), in the image's pixels.
struct EdgeQuadParams {
  float min_side = 0.0f;      // px on the image given
  float min_contrast = 0.0f;  // grey levels between a segment's dark and light sides
  // A side's segment ends within this fraction of its side of the corner (at least 2 px), except
  // at one covered corner, where the gap may be up to `max_covered_gap` of the side.
  float max_corner_gap = 0.0f;
  float max_covered_gap = 0.0f;
  int max_quads = 0;  // candidates a frame, the longest sides first
};

// Quads on `half` (an image at half the searched resolution or the searched image itself), their
// corners in `half`'s pixels, clockwise on screen; `occluded` set where a corner was closed across
// a gap. Quads whose centre lies inside one of `known` (same pixels) are left out.
std::vector<Quad> edgeSegmentQuads(const cv::Mat& half, const std::vector<Quad>& known,
                                   const EdgeQuadParams& params);

}  // namespace arbci::vision
