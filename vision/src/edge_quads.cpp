#include "edge_quads.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "quad_geometry.h"

namespace arbci::vision {
namespace {

struct Segment {
  cv::Point2f start, end, direction;  // dark side on the right of start -> end
  float length = 0.0f;
};

float grey(const cv::Mat& image, cv::Point2f p) {
  const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, image.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, image.rows - 1);
  return image.at<std::uint8_t>(y, x);
}

float cross(cv::Point2f a, cv::Point2f b) {
  return a.x * b.y - a.y * b.x;
}

// The segment oriented with its dark side on its right (y down: the right normal of (dx, dy) is
// (-dy, dx)), or nothing when its two sides differ by less than `min_contrast`.
std::optional<Segment> oriented(const cv::Mat& image, const cv::Vec4f& line, float min_contrast) {
  Segment s;
  s.start = {line[0], line[1]};
  s.end = {line[2], line[3]};
  const cv::Point2f d = s.end - s.start;
  s.length = std::hypot(d.x, d.y);
  if (s.length <= 0.0f) return std::nullopt;
  s.direction = d / s.length;
  const cv::Point2f right(-s.direction.y, s.direction.x);
  float on_right = 0.0f, on_left = 0.0f;
  for (const float t : {0.25f, 0.5f, 0.75f}) {
    const cv::Point2f p = s.start + d * t;
    on_right += grey(image, p + 2.0f * right);
    on_left += grey(image, p - 2.0f * right);
  }
  if (std::abs(on_right - on_left) < 3.0f * min_contrast) return std::nullopt;
  if (on_right > on_left) {
    std::swap(s.start, s.end);
    s.direction = -s.direction;
  }
  return s;
}

std::optional<cv::Point2f> intersection(const Segment& a, const Segment& b) {
  const float denominator = cross(a.direction, b.direction);
  if (std::abs(denominator) < 1e-6f) return std::nullopt;
  const float t = cross(b.start - a.start, b.direction) / denominator;
  return a.start + t * a.direction;
}

// How `a` leads into `b` at a corner turning right: 0 no, 1 the ends close, 2 across a gap as
// long as a covered corner.
int link(const Segment& a, const Segment& b, const EdgeQuadParams& p) {
  const float turn = cross(a.direction, b.direction);  // sine of the turn; right is positive
  if (turn < 0.5f) return 0;                           // 30 to 150 degrees
  const auto corner = intersection(a, b);
  if (!corner) return 0;
  // The corner lies ahead of a's end and behind b's start (a pixel of slack).
  const float past_a = (*corner - a.end).dot(a.direction);
  const float before_b = (b.start - *corner).dot(b.direction);
  if (past_a < -2.0f || before_b < -2.0f) return 0;
  const float gap = std::max(cv::norm(*corner - a.end), cv::norm(*corner - b.start));
  const float side = std::max(a.length, b.length);
  if (gap <= std::max(2.0f, p.max_corner_gap * side)) return 1;
  if (gap <= p.max_covered_gap * side) return 2;
  return 0;
}

}  // namespace

std::vector<Quad> edgeSegmentQuads(const cv::Mat& half, const std::vector<Quad>& known,
                                   const EdgeQuadParams& params) {
  std::vector<cv::Vec4f> lines;
  cv::createLineSegmentDetector(cv::LSD_REFINE_NONE)->detect(half, lines);
  std::vector<Segment> segments;
  const float shortest = 0.4f * params.min_side;
  for (const cv::Vec4f& line : lines) {
    if (std::hypot(line[2] - line[0], line[3] - line[1]) < shortest) continue;
    if (const auto s = oriented(half, line, params.min_contrast)) segments.push_back(*s);
  }
  // The longest first: a marker's sides are among the longest edges near it.
  std::sort(segments.begin(), segments.end(),
            [](const Segment& a, const Segment& b) { return a.length > b.length; });
  const size_t n = segments.size();
  std::vector<std::vector<std::pair<size_t, int>>> next(n);
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = 0; b < n; ++b) {
      if (a == b) continue;
      if (const int kind = link(segments[a], segments[b], params)) next[a].emplace_back(b, kind);
    }
  }
  std::vector<Quad> quads;
  auto taken = [&](cv::Point2f middle) {
    for (const Quad& q : known)
      if (insideConvex(q.corners, middle)) return true;
    for (const Quad& q : quads)
      if (insideConvex(q.corners, middle)) return true;
    return false;
  };
  for (size_t a = 0; a < n && static_cast<int>(quads.size()) < params.max_quads; ++a) {
    for (const auto& [b, ab] : next[a]) {
      if (b < a) continue;  // each cycle once, from its longest side
      for (const auto& [c, bc] : next[b]) {
        if (c < a || c == b) continue;
        if ((ab == 2) + (bc == 2) > 1) continue;
        for (const auto& [d, cd] : next[c]) {
          if (d < a || d == b || d == c) continue;
          if ((ab == 2) + (bc == 2) + (cd == 2) > 1) continue;
          const auto closing = std::find_if(next[d].begin(), next[d].end(),
                                            [&](const auto& e) { return e.first == a; });
          if (closing == next[d].end()) continue;
          const int gaps = (ab == 2) + (bc == 2) + (cd == 2) + (closing->second == 2);
          if (gaps > 1) continue;
          const std::array<const Segment*, 4> sides{&segments[a], &segments[b], &segments[c],
                                                    &segments[d]};
          Quad quad;
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            const auto corner = intersection(*sides[(k + 3) % 4], *sides[k]);
            ok = corner.has_value();
            if (ok) quad.corners[k] = *corner;
          }
          if (!ok) continue;
          // Each segment covers most of its side, every side is long enough.
          for (int k = 0; k < 4 && ok; ++k) {
            const float side =
                static_cast<float>(cv::norm(quad.corners[(k + 1) % 4] - quad.corners[k]));
            ok = side >= params.min_side && sides[k]->length >= 0.45f * side;
          }
          if (!ok) continue;
          if (signedQuadArea(quad.corners) <= 0.0f || taken(centre(quad.corners))) continue;
          quad.ideal_corners = quad.corners;
          quad.occluded = gaps == 1;
          quads.push_back(quad);
        }
      }
    }
  }
  return quads;
}

}  // namespace arbci::vision
