// Private: Moore-neighbour tracing of a dark component's outer boundary, clockwise on screen,
// starting at its top-most, left-most pixel.
#pragma once

#include <vector>

#include <opencv2/core/types.hpp>

#include "run_labeling.h"

namespace arbci::vision {

// Appends the boundary pixels to `contour` (cleared first). Returns false when the contour
// exceeds `max_length` pixels (not a compact shape worth fitting).
bool traceOuterContour(const RunLabeler& labels, cv::Point start, int max_length,
                       std::vector<cv::Point>& contour);

}  // namespace arbci::vision
