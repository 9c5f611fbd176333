#include "contour_trace.h"

namespace arbci::vision {
namespace {
// Clockwise on screen (y down): E, SE, S, SW, W, NW, N, NE.
constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
}  // namespace

bool traceOuterContour(const RunLabeler& labels, cv::Point start, int max_length,
                       std::vector<cv::Point>& contour) {
  contour.clear();
  const std::uint8_t* origin = labels.maskOrigin();
  const int stride = labels.maskStride();
  int offsets[8];
  for (int d = 0; d < 8; ++d) offsets[d] = kDx[d] + kDy[d] * stride;

  // From pixel `p`, whose white backtrack neighbour lies in direction `back`, find the next
  // boundary pixel clockwise; returns its direction or -1 for an isolated pixel.
  auto next = [&](const std::uint8_t* p, int back) {
    for (int k = 1; k <= 7; ++k) {
      const int d = (back + k) & 7;
      if (p[offsets[d]]) return d;
    }
    return -1;
  };

  cv::Point p = start;
  const std::uint8_t* here = origin + static_cast<ptrdiff_t>(start.y) * stride + start.x;
  int back = 4;  // the west neighbour of the top-left-most pixel is white
  int first_direction = -1;
  contour.push_back(p);
  while (true) {
    const int d = next(here, back);
    if (d < 0) return true;  // a single pixel
    if (p == start && static_cast<int>(contour.size()) > 1 && d == first_direction) {
      contour.pop_back();  // back at the start, about to repeat the first step
      return true;
    }
    if (first_direction < 0) first_direction = d;
    p += cv::Point(kDx[d], kDy[d]);
    here += offsets[d];
    // The last white neighbour examined, seen from the new pixel.
    back = (d & 1) ? (d + 5) & 7 : (d + 6) & 7;
    contour.push_back(p);
    if (static_cast<int>(contour.size()) > max_length) return false;
  }
}

}  // namespace arbci::vision
