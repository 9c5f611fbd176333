// Private: from a traced contour to a quadrilateral with sub-pixel corners. Four corners are
// found on the contour's convex hull by recursive splitting at the points farthest from the
// chords (the first is the one farthest from the component's first pixel, as ARToolKitPlus); the
// contour must follow the hull between them; a line is fitted
// to each side and then refined to the image's edge (the maximum of the intensity gradient across
// it), and the corners are the refined lines' intersections.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace arbci::vision {

class Undistorter;

struct Quad {
  // Clockwise on screen; corner 0 lies nearest the contour point farthest from the first pixel.
  std::array<cv::Point2f, 4> corners;        // image pixels
  std::array<cv::Point2f, 4> ideal_corners;  // undistorted pixels (the same without a lens)
  // Fitted from the visible runs of an outline partly covered (fitOccludedQuad): a corner of its
  // border may be hidden.
  bool occluded = false;
};

struct QuadFitParams {
  float min_side = 6.0f;  // px
  // Contour points may stray this fraction of a side's length (at least 2.5 px) from the chord,
  float max_side_deviation = 0.08f;
  // except those within this fraction of the outline's mean side of a corner: binarisation and
  // blur round and chamfer corners (an acute corner of a tilted marker in the halved frame by
  // 4.5 px, a sixth of that), and the sides are fitted and refined away from the corners. Each
  // larger allowance up to 0.3 read more tilted and blurred markers with no wrong id; beyond it the
  // gain was small and a corner may swallow a short side.
  float corner_allowance = 0.3f;
  bool refine_edges = true;
  // With a lens, sides are fitted as straight lines in undistorted coordinates (ARToolKitPlus
  // undistorts contour points before fitting), so curved edges of a distorting lens fit exactly.
  const Undistorter* lens = nullptr;
};

struct QuadFit {
  std::optional<Quad> quad;
  // The contour's convex hull is a quadrilateral even if the contour is not: the outline of a
  // square whose border is broken or dented (worth binarising again), rather than of clutter.
  bool hull_is_quadrilateral = false;
  // Then the hull's four corners (contour pixels, in contour order).
  std::array<cv::Point, 4> hull_corners{};
};

QuadFit fitQuad(const std::vector<cv::Point>& contour, cv::Point first_pixel, const cv::Mat& image,
                const QuadFitParams& params);

// A quadrilateral found elsewhere (e.g. on a reduced image, corners scaled to `image`'s pixels,
// clockwise) with its sides moved onto `image`'s edges as fitQuad() does; nullopt when the
// refined sides no longer make a convex quadrilateral with sides of at least `min_side`.
std::optional<Quad> refineQuad(const std::array<cv::Point2f, 4>& corners, const cv::Mat& image,
                               const QuadFitParams& params);

// A marker whose outline is no quadrilateral because something covers part of it (a finger over
// a corner, dark or light): its four longest straight runs, in order around the outline, fitted
// as lines and intersected, as line-based detectors find squares; nullopt unless they make a
// convex quadrilateral that the runs mostly cover.
// `cut_open`: a light occluder may have cut the outline open (the component encloses nothing):
// when its polygon gives no sides, the outline's convex hull, which skips the cut, is tried too.
std::optional<Quad> fitOccludedQuad(const std::vector<cv::Point>& contour, const cv::Mat& image,
                                    const QuadFitParams& params, bool cut_open);

}  // namespace arbci::vision
