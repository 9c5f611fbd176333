// Private: a 3x3 binomial blur ([1 2 1] / 4 in each direction) of an 8-bit image, used before
// binarisation and edge refinement to suppress sensor noise without moving edges.
#pragma once

#include <opencv2/core/mat.hpp>

namespace arbci::vision {

void smoothBinomial3(const cv::Mat& src, cv::Mat& dst);

// True when the grey level jumps more across the lines of an 8 px grid than beside them: the
// block edges a JPEG (e.g. an MJPEG webcam's) leaves. Smoothing then keeps them from breaking
// a blurred marker's border into pieces.
bool looksBlockCompressed(const cv::Mat& gray);

}  // namespace arbci::vision
