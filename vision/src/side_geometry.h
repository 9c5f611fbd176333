// Private: the geometry shared by the ways a quad's sides are moved onto the image's edges
// (quad_fit.cpp's edge refinement, blurred_edges.cpp's placement on motion-blurred edges): the
// lens mapping, lines and their fit and intersections, and the final convexity check.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <opencv2/core/types.hpp>

#include "arbci/vision/undistortion.h"
#include "image_sampling.h"
#include "quad_fit.h"

namespace arbci::vision::side_geometry {

// Image <-> ideal coordinates through the lens; the identity without one.
struct LensMap {
  const Undistorter* lens = nullptr;
  cv::Point2f toIdeal(cv::Point2f p) const {
    if (!lens) return p;
    const cv::Point2d q = lens->undistort(p);
    return {static_cast<float>(q.x), static_cast<float>(q.y)};
  }
  cv::Point2f toImage(cv::Point2f p) const {
    if (!lens) return p;
    const cv::Point2d q = lens->distort(p);
    return {static_cast<float>(q.x), static_cast<float>(q.y)};
  }
};

struct Line {
  cv::Point2f point;      // a point on the line
  cv::Point2f direction;  // unit length
};

inline float length(cv::Point2f v) {
  return std::sqrt(v.dot(v));
}

// Weighted total-least-squares line through `count` points.
inline std::optional<Line> fitLine(const cv::Point2f* points, const float* weights, int count) {
  double sw = 0, sx = 0, sy = 0;
  for (int i = 0; i < count; ++i) {
    sw += weights[i];
    sx += weights[i] * points[i].x;
    sy += weights[i] * points[i].y;
  }
  if (count < 2 || sw <= 0) return std::nullopt;
  const double mx = sx / sw, my = sy / sw;
  double cxx = 0, cxy = 0, cyy = 0;
  for (int i = 0; i < count; ++i) {
    const double dx = points[i].x - mx, dy = points[i].y - my;
    cxx += weights[i] * dx * dx;
    cxy += weights[i] * dx * dy;
    cyy += weights[i] * dy * dy;
  }
  // Principal axis of the 2x2 scatter matrix, at angle a = atan2(2 cxy, cxx - cyy) / 2 (in
  // (-90, 90] degrees), from cos 2a and sin 2a by the half-angle formulas.
  const double diagonal = cxx - cyy, r = std::sqrt(diagonal * diagonal + 4.0 * cxy * cxy);
  const double cos2 = r > 0.0 ? diagonal / r : 1.0;
  const double c = std::sqrt(std::max(0.0, 0.5 * (1.0 + cos2)));
  const double s = std::copysign(std::sqrt(std::max(0.0, 0.5 * (1.0 - cos2))), cxy);
  return Line{cv::Point2f(static_cast<float>(mx), static_cast<float>(my)),
              cv::Point2f(static_cast<float>(c), static_cast<float>(s))};
}

inline std::optional<cv::Point2f> intersect(const Line& a, const Line& b) {
  const float det = a.direction.x * b.direction.y - a.direction.y * b.direction.x;
  if (std::abs(det) < 1e-6f) return std::nullopt;
  const cv::Point2f d = b.point - a.point;
  const float t = (d.x * b.direction.y - d.y * b.direction.x) / det;
  return a.point + t * a.direction;
}

// The unit vector in the image that `ideal_outward` (a unit vector at `ideal_base`, ideal
// coordinates) becomes as the lens bends it.
inline cv::Point2f outwardInImage(const LensMap& lens, cv::Point2f ideal_base,
                                  cv::Point2f ideal_outward) {
  if (!lens.lens) return ideal_outward;
  cv::Point2f outward = lens.toImage(ideal_base + 0.5f * ideal_outward) -
                        lens.toImage(ideal_base - 0.5f * ideal_outward);
  return outward / std::max(1e-6f, std::sqrt(outward.dot(outward)));
}

// The corners where consecutive lines meet (corner k between side k - 1 and side k).
inline bool intersectLines(const std::array<Line, 4>& lines, std::array<cv::Point2f, 4>& corners) {
  for (int k = 0; k < 4; ++k) {
    const auto corner = intersect(lines[(k + 3) % 4], lines[k]);
    if (!corner) return false;
    corners[k] = *corner;
  }
  return true;
}

// A marker is a convex quadrilateral with sides of a usable length: then `quad`'s ideal corners
// are its corners, which become image coordinates.
inline bool finishQuad(const QuadFitParams& params, const LensMap& lens, Quad& quad) {
  float sign = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f e1 = quad.corners[(k + 1) % 4] - quad.corners[k];
    const cv::Point2f e2 = quad.corners[(k + 2) % 4] - quad.corners[(k + 1) % 4];
    if (length(e1) < params.min_side) return false;
    const float cross = e1.x * e2.y - e1.y * e2.x;
    if (sign == 0.0f) sign = cross;
    if (cross * sign <= 0.0f) return false;
  }
  quad.ideal_corners = quad.corners;
  for (int k = 0; k < 4; ++k) quad.corners[k] = lens.toImage(quad.ideal_corners[k]);
  return true;
}

// The region sampled around the sides from corner to corner (ideal coordinates, as the lens
// bends them into the image), grown by `margin` px.
inline cv::Rect2f sidesRegion(const LensMap& lens, const std::array<cv::Point2f, 4>& corners,
                              float margin) {
  std::array<cv::Point2f, 20> outline;
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j < 5; ++j)
      outline[5 * k + j] =
          lens.toImage(corners[k] + (corners[(k + 1) % 4] - corners[k]) * (j / 5.0f));
  }
  return boundsOf(outline, margin);
}

}  // namespace arbci::vision::side_geometry
