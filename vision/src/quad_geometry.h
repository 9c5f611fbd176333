// Private: the small plane-geometry helpers the square search's passes share (quads as four
// corners clockwise on screen, boxes of the searched image).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/core/types.hpp>

namespace arbci::vision {

using QuadCorners = std::array<cv::Point2f, 4>;

inline bool insideConvex(const QuadCorners& quad, cv::Point2f p) {
  float sign = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f e = quad[(k + 1) % 4] - quad[k];
    const cv::Point2f d = p - quad[k];
    const float cross = e.x * d.y - e.y * d.x;
    if (sign == 0.0f) sign = cross;
    if (cross * sign < 0.0f) return false;
  }
  return true;
}

// Positive when the corners run clockwise on screen (y down).
inline float signedQuadArea(const QuadCorners& q) {
  float area = 0.0f;
  for (int k = 0; k < 4; ++k) area += q[k].x * q[(k + 1) % 4].y - q[(k + 1) % 4].x * q[k].y;
  return area * 0.5f;
}

inline float quadArea(const QuadCorners& q) {
  return std::abs(signedQuadArea(q));
}

inline float longestSide(const QuadCorners& q) {
  float longest = 0.0f;
  for (int k = 0; k < 4; ++k)
    longest = std::max(longest, static_cast<float>(cv::norm(q[(k + 1) % 4] - q[k])));
  return longest;
}

inline cv::Point2f centre(const QuadCorners& q) {
  return (q[0] + q[1] + q[2] + q[3]) * 0.25f;
}

// `box` grown by `margin` px on every side.
inline cv::Rect grown(const cv::Rect& box, int margin) {
  return {box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin};
}

// The whole pixels `q` covers: cv::boundingRect's result, without its InputArray set-up (called
// for every quad at every near miss, that set-up alone was a measurable share of a frame).
inline cv::Rect pixelBox(const QuadCorners& q) {
  float min_x = q[0].x, max_x = q[0].x, min_y = q[0].y, max_y = q[0].y;
  for (const cv::Point2f& p : q) {
    min_x = std::min(min_x, p.x);
    max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  const cv::Point from(static_cast<int>(std::floor(min_x)), static_cast<int>(std::floor(min_y)));
  const cv::Point to(static_cast<int>(std::floor(max_x)) + 1,
                     static_cast<int>(std::floor(max_y)) + 1);
  return {from, to};
}

inline cv::Point2f toFloat(cv::Point2d p) {
  return {static_cast<float>(p.x), static_cast<float>(p.y)};
}

}  // namespace arbci::vision
