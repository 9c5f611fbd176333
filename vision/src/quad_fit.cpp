#include "quad_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

#include "image_sampling.h"
#include "side_geometry.h"

namespace arbci::vision {

using namespace side_geometry;

namespace {

// The least a side may stray from its chord, px. Blur rounds a small square's corners, bending the
// ends of its sides: blurred (sigma 1.5) 20-30 px markers stray up to 2.2 px from their chords.
constexpr float kMinSideDeviation = 2.5f;

// Edge points per side when the sides are moved onto the image's edges: the first pass only
// brings them within a pixel or two, the second fits them. Fewer in the first pass saves little
// time and lets a steeply tilted marker's side settle on the wrong edge (a pose flip).
constexpr int kFirstPassSamples = 14, kSecondPassSamples = 20;

// Index of the contour point in the forward arc (from, to) farthest from the chord from-to, and
// its distance; the arc's ends up to the first point farther than `end_radius` from their corner
// are left out (-1 and 0 when no point is left).
int farthestFromChord(const std::vector<cv::Point>& contour, int from, int to, float& distance,
                      float end_radius = 0.0f) {
  const int n = static_cast<int>(contour.size());
  const cv::Point a = contour[from], b = contour[to];
  auto squared = [](cv::Point v) {
    return static_cast<std::int64_t>(v.x) * v.x + static_cast<std::int64_t>(v.y) * v.y;
  };
  const auto radius_squared = static_cast<std::int64_t>(end_radius * end_radius);
  // The arc's points left: offsets first..last from `from`, the first of them at index `start`.
  int first = 1, last = (to - from + n) % n - 1;
  int start = from + 1 == n ? 0 : from + 1, end = to == 0 ? n - 1 : to - 1;
  for (; first <= last && squared(contour[start] - a) <= radius_squared; ++first)
    start = start + 1 == n ? 0 : start + 1;
  for (; last >= first && squared(contour[end] - b) <= radius_squared; --last)
    end = end == 0 ? n - 1 : end - 1;
  const cv::Point chord = b - a;
  const bool point_chord = chord.x == 0 && chord.y == 0;
  int best = -1;
  std::int64_t best_measure = -1;
  // |chord x p| is the distance times the chord's length (exact in integers); for a chord of one
  // point, the squared distance.
  auto scan = [&](int begin, int stop) {
    for (int i = begin; i < stop; ++i) {
      const cv::Point p = contour[i] - a;
      const std::int64_t measure = point_chord ? squared(p)
                                               : std::abs(static_cast<std::int64_t>(chord.x) * p.y -
                                                          static_cast<std::int64_t>(chord.y) * p.x);
      if (measure > best_measure) {
        best_measure = measure;
        best = i;
      }
    }
  };
  const int count = last - first + 1;
  if (count > 0) {
    const int head = std::min(count, n - start);
    scan(start, start + head);
    scan(0, count - head);
  }
  if (best < 0) {
    distance = 0.0f;
  } else if (point_chord) {
    distance = std::sqrt(static_cast<float>(best_measure));
  } else {
    distance = static_cast<float>(best_measure) / length(cv::Point2f(chord));
  }
  return best;
}

// True when the outline's sides from each corner to the next stay within `tolerance` of their
// chords, but within `corner_radius` of a corner.
bool sidesFollowChords(const std::vector<cv::Point>& outline, const std::array<int, 4>& corners,
                       float corner_radius, float tolerance) {
  for (int k = 0; k < 4; ++k) {
    float deviation = 0.0f;
    farthestFromChord(outline, corners[k], corners[(k + 1) % 4], deviation, corner_radius);
    if (deviation > tolerance) return false;
  }
  return true;
}

std::vector<int>& scratchIndices() {
  thread_local std::vector<int> indices;
  return indices;
}

// Of the candidate vertices (in contour order), the four spanning the largest area, in order.
std::array<int, 4> largestQuadrilateral(const std::vector<cv::Point>& contour,
                                        const std::vector<int>& candidates) {
  const int m = static_cast<int>(candidates.size());
  std::array<int, 4> best{candidates[0], candidates[1 % m], candidates[2 % m], candidates[3 % m]};
  double best_area = -1.0;
  auto twiceArea = [&](int a, int b, int c, int d) {
    const cv::Point p[4] = {contour[a], contour[b], contour[c], contour[d]};
    double area = 0.0;
    for (int k = 0; k < 4; ++k) {
      area += static_cast<double>(p[k].x) * p[(k + 1) % 4].y -
              static_cast<double>(p[(k + 1) % 4].x) * p[k].y;
    }
    return std::abs(area);
  };
  for (int a = 0; a < m; ++a) {
    for (int b = a + 1; b < m; ++b) {
      for (int c = b + 1; c < m; ++c) {
        for (int d = c + 1; d < m; ++d) {
          const double area = twiceArea(candidates[a], candidates[b], candidates[c], candidates[d]);
          if (area > best_area) {
            best_area = area;
            best = {candidates[a], candidates[b], candidates[c], candidates[d]};
          }
        }
      }
    }
  }
  // Keep corner 0 the one nearest the start of the candidate list (the ARToolKitPlus vertex).
  const auto first = std::find(best.begin(), best.end(), candidates[0]);
  if (first != best.end()) std::rotate(best.begin(), first, best.end());
  return best;
}

std::vector<int>& scratchHullIndices() {
  thread_local std::vector<int> indices;
  return indices;
}

std::vector<cv::Point>& scratchHull() {
  thread_local std::vector<cv::Point> hull;
  return hull;
}

std::vector<cv::Point2f>& scratchPoints() {
  thread_local std::vector<cv::Point2f> points;
  return points;
}

std::vector<float>& scratchWeights() {
  thread_local std::vector<float> weights;
  return weights;
}

// Appends, in contour order, the vertices of the forward arc (from, to) found by recursive
// splitting; false once more than `limit` vertices are found (not a quadrilateral).
bool splitArc(const std::vector<cv::Point>& contour, int from, int to, float tolerance,
              size_t limit, std::vector<int>& vertices) {
  float distance = 0.0f;
  const int split = farthestFromChord(contour, from, to, distance);
  if (split < 0 || distance <= tolerance) return true;
  if (!splitArc(contour, from, split, tolerance, limit, vertices)) return false;
  vertices.push_back(split);
  if (vertices.size() > limit) return false;
  return splitArc(contour, split, to, tolerance, limit, vertices);
}

// Moves the side from `a` to `b` onto the image edge: at points along the side, the offset across
// it (within +-radius px) where the intensity rises fastest (dark inside, light outside) is found
// to sub-pixel precision by a parabola, and a line is fitted to those edge points weighted by the
// rise.
// `a` and `b` are ideal coordinates; profiles are sampled in the image across the side as the lens
// bends it, and the edge points are fitted in ideal coordinates.
std::optional<Line> refineSide(const BilinearSampler& sample, const LensMap& lens, cv::Point2f a,
                               cv::Point2f b, int radius, int most_samples) {
  constexpr int kMaxSamples = 20, kMaxRadius = 4;
  const cv::Point2f d = b - a;
  const float length = std::sqrt(d.dot(d));
  if (length < 4.0f) return std::nullopt;
  radius = std::min(radius, kMaxRadius);
  const cv::Point2f along = d / length;
  const cv::Point2f ideal_outward(along.y, -along.x);  // clockwise on screen: the interior is right
  const int samples =
      std::clamp(static_cast<int>(length / 2.5f), 5, std::min(most_samples, kMaxSamples));
  const float end = std::min(0.3f, std::max(0.05f, (static_cast<float>(radius) + 1.0f) / length));
  // Where each profile starts and runs, then every profile sampled, four at a time (the last
  // group padded with copies of the last profile).
  constexpr int kPadded = kMaxSamples + 3, kProfileLength = 2 * kMaxRadius + 4;
  cv::Point2f bases[kPadded], outwards[kPadded];
  float from_x[kPadded], from_y[kPadded], out_x[kPadded], out_y[kPadded];
  for (int s = 0; s < samples; ++s) {
    // Stay clear of the corners, where the profile would cross the neighbouring side.
    const float t =
        end + (1.0f - 2.0f * end) * (static_cast<float>(s) + 0.5f) / static_cast<float>(samples);
    const cv::Point2f ideal_base = a + t * d;
    bases[s] = lens.toImage(ideal_base);
    outwards[s] = outwardInImage(lens, ideal_base, ideal_outward);
    const cv::Point2f from = bases[s] - static_cast<float>(radius + 1) * outwards[s];
    from_x[s] = from.x;
    from_y[s] = from.y;
    out_x[s] = outwards[s].x;
    out_y[s] = outwards[s].y;
  }
  for (int s = samples; s % 4 != 0; ++s) {
    from_x[s] = from_x[samples - 1];
    from_y[s] = from_y[samples - 1];
    out_x[s] = out_x[samples - 1];
    out_y[s] = out_y[samples - 1];
  }
  float profiles[kPadded][kProfileLength];
  for (int s = 0; s < samples; s += 4) {
    sample.lines4(&from_x[s], &from_y[s], &out_x[s], &out_y[s], 2 * radius + 3, profiles[s],
                  kProfileLength);
  }
  cv::Point2f points[kMaxSamples];
  float weights[kMaxSamples];
  int count = 0;
  float rise[2 * kMaxRadius + 1];
  for (int s = 0; s < samples; ++s) {
    const float* profile = profiles[s];
    const cv::Point2f base = bases[s], outward = outwards[s];
    int best = 0;
    float best_rise = 0.0f;
    for (int k = -radius; k <= radius; ++k) {
      rise[k + radius] = profile[k + radius + 2] - profile[k + radius];
      if (rise[k + radius] > best_rise) {
        best_rise = rise[k + radius];
        best = k;
      }
    }
    if (best_rise <= 4.0f) continue;
    // The edge: where the profile crosses the middle of its dark and light extremes, searched
    // outward from the steepest rise (linear interpolation between samples).
    float lo = profile[0], hi = profile[0];
    for (int k = 0; k < 2 * radius + 3; ++k) {
      lo = std::min(lo, profile[k]);
      hi = std::max(hi, profile[k]);
    }
    const float middle = 0.5f * (lo + hi);
    float offset = static_cast<float>(best);
    for (int k = -radius - 1; k <= radius; ++k) {
      const float a = profile[k + radius + 1], b = profile[k + radius + 2];
      if (a <= middle && b > middle &&
          std::abs(static_cast<float>(k) + 0.5f - static_cast<float>(best)) <= 1.5f) {
        offset = static_cast<float>(k) + (middle - a) / (b - a);
        break;
      }
    }
    points[count] = lens.toIdeal(base + offset * outward);
    weights[count] = best_rise;
    ++count;
  }
  if (count < 3) return std::nullopt;
  return fitLine(points, weights, count);
}

// Moves the sides onto the image's edges, twice (the second time with a reach of at most 2 px),
// and intersects them again; `corners` are ideal coordinates. False when sides no longer meet.
bool refineToEdges(const cv::Mat& image, const LensMap& lens, std::array<Line, 4>& lines,
                   std::array<cv::Point2f, 4>& corners) {
  // The search reaches at most a tenth of the smallest side across the edge (1..3 px).
  float shortest = length(corners[1] - corners[0]);
  for (int k = 1; k < 4; ++k)
    shortest = std::min(shortest, length(corners[(k + 1) % 4] - corners[k]));
  const int reach = std::clamp(static_cast<int>(std::lround(0.1f * shortest)), 1, 3);
  for (int pass = 0; pass < 2; ++pass) {
    const int radius = pass == 0 ? reach : std::min(reach, 2);
    // Samples lie within radius + 1 px of the current sides (as the lens bends them).
    const BilinearSampler sample(image, sidesRegion(lens, corners, static_cast<float>(radius + 2)));
    std::array<Line, 4> refined = lines;
    for (int k = 0; k < 4; ++k) {
      const auto line = refineSide(sample, lens, corners[k], corners[(k + 1) % 4], radius,
                                   pass == 0 ? kFirstPassSamples : kSecondPassSamples);
      if (line) refined[k] = *line;
    }
    lines = refined;
    if (!intersectLines(lines, corners)) return false;
  }
  return true;
}

// Indices into `outline` (a closed polygon, clockwise) of the corners of the quadrilateral it
// outlines. Candidate vertices come from recursive splitting at the point farthest from the chord
// (ARToolKit's method, with a fine tolerance so that rounded or chamfered corners still yield a
// vertex), starting from `first` and the point farthest from it; the corners are the four
// candidates spanning the largest area, and every outline point must lie close to its side.
std::optional<std::array<int, 4>> quadVertices(const std::vector<cv::Point>& outline, int first,
                                               float side_estimate, float max_side_deviation,
                                               float corner_allowance) {
  const int n = static_cast<int>(outline.size());
  if (n < 4) return std::nullopt;
  int second = first;
  float farthest = -1.0f;
  for (int i = 0; i < n; ++i) {
    const cv::Point2f d(outline[i] - outline[first]);
    if (d.dot(d) > farthest) {
      farthest = d.dot(d);
      second = i;
    }
  }
  std::vector<int>& candidates = scratchIndices();
  constexpr size_t kMaxCandidates = 10;
  float tolerance = std::max(1.0f, 0.03f * side_estimate);
  for (int round = 0;; ++round) {
    candidates.clear();
    candidates.push_back(first);
    bool few = splitArc(outline, first, second, tolerance, kMaxCandidates, candidates);
    candidates.push_back(second);
    few = few && splitArc(outline, second, first, tolerance, kMaxCandidates, candidates);
    if (few && candidates.size() <= kMaxCandidates) break;
    if (round == 2) return std::nullopt;  // too ragged to be a square
    tolerance *= 2.0f;
  }
  if (candidates.size() < 4) return std::nullopt;
  const std::array<int, 4> vertex = largestQuadrilateral(outline, candidates);
  const float max_deviation = std::max(kMinSideDeviation, max_side_deviation * side_estimate);
  if (!sidesFollowChords(outline, vertex, corner_allowance * side_estimate, max_deviation))
    return std::nullopt;
  return vertex;
}

// The convex hull of a contour as contour indices, clockwise on screen. Only the leftmost and
// rightmost contour point of each row can be a hull vertex, and they come sorted by row, so
// Andrew's monotone chain runs in time linear in the contour (no sort).
void convexHullOfContour(const std::vector<cv::Point>& contour, std::vector<int>& hull) {
  int y0 = contour[0].y, y1 = y0;
  for (const cv::Point& p : contour) {
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  const int rows = y1 - y0 + 1;
  thread_local std::vector<int> left, right, down, up;
  left.assign(static_cast<size_t>(rows), -1);
  right.assign(static_cast<size_t>(rows), -1);
  for (int i = 0; i < static_cast<int>(contour.size()); ++i) {
    const int r = contour[i].y - y0;
    if (left[r] < 0 || contour[i].x < contour[left[r]].x) left[r] = i;
    if (right[r] < 0 || contour[i].x > contour[right[r]].x) right[r] = i;
  }
  // Andrew's monotone chain, its points taken row by row (so already in (y, x) order): the right
  // side going down, then the left side going up, keeping only turns to the right on screen
  // (clockwise with y pointing down). A row's leftmost point lies left of the right side and its
  // rightmost right of the left side (but in the top and bottom rows, where the sides meet), so
  // each side is chained from the points that can lie on it: the same hull from half the points.
  down.clear();  // the first point, then each row's rightmost
  up.clear();    // each row's leftmost but the last point, from the bottom up
  auto wide = [&](int r) { return contour[right[r]].x != contour[left[r]].x; };
  down.push_back(left[0]);
  if (wide(0)) down.push_back(right[0]);
  for (int r = 1; r < rows; ++r) down.push_back(right[r]);
  if (wide(rows - 1)) up.push_back(left[rows - 1]);
  for (int r = rows - 2; r >= 0; --r) up.push_back(left[r]);
  auto cross = [&](int o, int a, int b) {
    const cv::Point oa = contour[a] - contour[o], ob = contour[b] - contour[o];
    return static_cast<std::int64_t>(oa.x) * ob.y - static_cast<std::int64_t>(oa.y) * ob.x;
  };
  hull.clear();
  for (int i : down) {
    while (hull.size() >= 2 && cross(hull[hull.size() - 2], hull.back(), i) <= 0) hull.pop_back();
    hull.push_back(i);
  }
  const size_t right_side = hull.size() + 1;
  for (int i : up) {
    while (hull.size() >= right_side && cross(hull[hull.size() - 2], hull.back(), i) <= 0)
      hull.pop_back();
    hull.push_back(i);
  }
  hull.pop_back();  // the first point again
}

float perimeterOf(const std::vector<cv::Point>& outline) {
  const int n = static_cast<int>(outline.size());
  float perimeter = 0.0f;
  for (int i = 0; i < n; ++i) perimeter += length(cv::Point2f(outline[(i + 1) % n] - outline[i]));
  return perimeter;
}

}  // namespace

QuadFit fitQuad(const std::vector<cv::Point>& contour, cv::Point first_pixel, const cv::Mat& image,
                const QuadFitParams& params) {
  QuadFit result;
  const int n = static_cast<int>(contour.size());
  if (n < 8) return result;
  // Corners are looked for on the convex hull (a few dozen points, where a square's corners are
  // plain); its vertices keep their contour indices.
  std::vector<int>& hull_index = scratchHullIndices();
  std::vector<cv::Point>& hull = scratchHull();
  convexHullOfContour(contour, hull_index);
  const int m = static_cast<int>(hull_index.size());
  if (m < 4) return result;
  hull.resize(static_cast<size_t>(m));
  int first = 0;  // ARToolKitPlus's first vertex: farthest from the component's first pixel
  float farthest = -1.0f;
  for (int i = 0; i < m; ++i) {
    hull[i] = contour[hull_index[i]];
    const cv::Point2f d(hull[i] - first_pixel);
    if (d.dot(d) > farthest) {
      farthest = d.dot(d);
      first = i;
    }
  }
  const float side_estimate = perimeterOf(hull) / 4.0f;
  const auto corners =
      quadVertices(hull, first, side_estimate, params.max_side_deviation, params.corner_allowance);
  if (!corners) return result;
  result.hull_is_quadrilateral = true;
  std::array<int, 4> vertex;
  for (int k = 0; k < 4; ++k) {
    vertex[k] = hull_index[(*corners)[k]];
    result.hull_corners[k] = contour[vertex[k]];
  }
  // Every side as long as a marker's (checked first: it is cheap, and a third to a half of the
  // solid components that fail, fail here).
  for (int k = 0; k < 4; ++k) {
    if (length(cv::Point2f(result.hull_corners[(k + 1) % 4] - result.hull_corners[k])) <
        params.min_side)
      return result;
  }
  // The contour must follow the hull's sides: the vertices in contour order, and no dent deeper
  // than the tolerance away from the corners (a broken border or a notch is not a square, though
  // its hull is; a rounded corner is).
  for (int k = 0; k < 4; ++k) {
    const int step = (vertex[(k + 1) % 4] - vertex[k] + n) % n,
              next = (vertex[(k + 2) % 4] - vertex[k] + n) % n;
    if (step == 0 || next <= step) return result;
  }
  const float max_deviation =
      std::max(kMinSideDeviation, params.max_side_deviation * side_estimate);
  if (!sidesFollowChords(contour, vertex, params.corner_allowance * side_estimate, max_deviation))
    return result;

  // A line through each side's contour arc, its ends trimmed.
  const LensMap lens{params.lens};
  std::array<Line, 4> lines;
  std::vector<cv::Point2f>& side_points = scratchPoints();
  std::vector<float>& unit_weights = scratchWeights();
  for (int k = 0; k < 4; ++k) {
    const int from = vertex[k], to = vertex[(k + 1) % 4];
    const int count = (to - from + n) % n;
    const int trim = std::max(1, count / 8);
    side_points.clear();
    for (int j = trim; j <= count - trim; ++j)
      side_points.push_back(lens.toIdeal(contour[(from + j) % n]));
    unit_weights.assign(side_points.size(), 1.0f);
    const auto line =
        fitLine(side_points.data(), unit_weights.data(), static_cast<int>(side_points.size()));
    if (!line || side_points.size() < 2) return result;
    lines[k] = *line;
  }

  // From here on, corners are ideal coordinates.
  Quad quad;
  if (!intersectLines(lines, quad.corners)) return result;
  // Corners far from their contour vertices mean the sides were not straight lines.
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f d = quad.corners[k] - lens.toIdeal(cv::Point2f(contour[vertex[k]]));
    const float side = length(quad.corners[(k + 1) % 4] - quad.corners[k]);
    if (length(d) > 2.0f + 0.25f * side) return result;
  }

  if (params.refine_edges && !refineToEdges(image, lens, lines, quad.corners)) return result;

  if (!finishQuad(params, lens, quad)) return result;
  result.quad = quad;
  return result;
}

std::optional<Quad> refineQuad(const std::array<cv::Point2f, 4>& corners, const cv::Mat& image,
                               const QuadFitParams& params) {
  const LensMap lens{params.lens};
  Quad quad;
  for (int k = 0; k < 4; ++k) quad.corners[k] = lens.toIdeal(corners[k]);
  std::array<Line, 4> lines;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f d = quad.corners[(k + 1) % 4] - quad.corners[k];
    const float n = length(d);
    if (n <= 0.0f) return std::nullopt;
    lines[k] = {quad.corners[k], d / n};
  }
  if (params.refine_edges && !refineToEdges(image, lens, lines, quad.corners)) return std::nullopt;
  if (!finishQuad(params, lens, quad)) return std::nullopt;
  return quad;
}

namespace {

// The sides of an occluded outline from `polygon`, a simplification of it whose vertices are
// contour points in contour order (`at`: their contour indices): its four longest edges, fitted on
// the contour between their ends and intersected.
std::optional<Quad> occludedQuadFromPolygon(const std::vector<cv::Point>& contour,
                                            const std::vector<cv::Point>& polygon,
                                            const std::vector<int>& at, float perimeter,
                                            const cv::Mat& image, const QuadFitParams& params) {
  const int n = static_cast<int>(contour.size());
  const int m = static_cast<int>(polygon.size());
  struct Run {
    int from, to;  // contour indices
    float length;
  };
  std::vector<Run> runs;
  for (int v = 0; v < m; ++v) {
    const int w = (v + 1) % m;
    runs.push_back({at[v], at[w], length(cv::Point2f(polygon[w] - polygon[v]))});
  }
  // The four longest runs, each at least a third of a quarter of the outline, in outline order.
  std::vector<int> order(runs.size());
  for (size_t r = 0; r < runs.size(); ++r) order[r] = static_cast<int>(r);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return runs[a].length > runs[b].length; });
  if (runs[order[3]].length < std::max(params.min_side * 0.5f, perimeter / 12.0f))
    return std::nullopt;
  std::array<int, 4> chosen{order[0], order[1], order[2], order[3]};
  std::sort(chosen.begin(), chosen.end());
  // Sides meet at corners that turn the same way, by 20 to 160 degrees (a square in perspective).
  const LensMap lens{params.lens};
  std::array<Line, 4> lines;
  std::vector<cv::Point2f>& side_points = scratchPoints();
  std::vector<float>& unit_weights = scratchWeights();
  for (int k = 0; k < 4; ++k) {
    const Run& run = runs[static_cast<size_t>(chosen[k])];
    const int count = (run.to - run.from + n) % n;
    const int trim = std::max(1, count / 8);
    side_points.clear();
    for (int j = trim; j <= count - trim; ++j)
      side_points.push_back(lens.toIdeal(contour[(run.from + j) % n]));
    unit_weights.assign(side_points.size(), 1.0f);
    const auto line =
        fitLine(side_points.data(), unit_weights.data(), static_cast<int>(side_points.size()));
    if (!line || side_points.size() < 3) return std::nullopt;
    lines[k] = *line;
    // A side is straight along its whole run: a dent in the middle of a side (a notch, a bite)
    // is no covered corner. (The polygon's own runs are straight by construction; a run between
    // two vertices of the outline's hull need not be.)
    const float allowed = std::max(2.0f, 0.04f * run.length);
    for (const cv::Point2f& p : side_points) {
      const cv::Point2f d = p - line->point;
      if (std::abs(d.x * line->direction.y - d.y * line->direction.x) > allowed)
        return std::nullopt;
    }
    // Directed along the outline, so consecutive sides turn one way.
    if (lines[k].direction.dot(cv::Point2f(contour[run.to] - contour[run.from])) < 0.0f)
      lines[k].direction = -lines[k].direction;
  }
  float turn_sign = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f a = lines[k].direction, b = lines[(k + 1) % 4].direction;
    const float cross = a.x * b.y - a.y * b.x;
    const float angle = std::abs(std::atan2(cross, a.dot(b))) * 180.0f / 3.14159265f;
    if (angle < 20.0f || angle > 160.0f) return std::nullopt;
    if (turn_sign == 0.0f) turn_sign = cross;
    if (cross * turn_sign <= 0.0f) return std::nullopt;
  }
  Quad quad;
  if (!intersectLines(lines, quad.corners)) return std::nullopt;
  // Each run covers most of its side (a covered corner shortens two sides by a quarter at most),
  // and the corners lie near the outline: a covered one within a third of a side of it.
  for (int k = 0; k < 4; ++k) {
    const float side = length(quad.corners[(k + 1) % 4] - quad.corners[k]);
    if (side < params.min_side) return std::nullopt;
    if (runs[static_cast<size_t>(chosen[k])].length < 0.45f * side) return std::nullopt;
    float nearest = 1e30f;
    for (int i = 0; i < n; i += 2)
      nearest = std::min(nearest, length(lens.toIdeal(cv::Point2f(contour[i])) - quad.corners[k]));
    if (nearest > 2.0f + side / 3.0f) return std::nullopt;
  }
  if (params.refine_edges && !refineToEdges(image, lens, lines, quad.corners)) return std::nullopt;
  if (!finishQuad(params, lens, quad)) return std::nullopt;
  quad.occluded = true;
  return quad;
}

// Each of `polygon`'s points' index on `contour`, searched forward from the last (the polygon's
// points are contour points in contour order); empty when one is not found.
std::vector<int> contourIndices(const std::vector<cv::Point>& contour,
                                const std::vector<cv::Point>& polygon) {
  const int n = static_cast<int>(contour.size());
  std::vector<int> at(polygon.size(), -1);
  for (size_t v = 0, i = 0; v < polygon.size(); ++v) {
    for (int tries = 0; tries < n && contour[i] != polygon[v]; ++tries) i = (i + 1) % n;
    if (contour[i] != polygon[v]) return {};
    at[v] = static_cast<int>(i);
  }
  return at;
}

}  // namespace

std::optional<Quad> fitOccludedQuad(const std::vector<cv::Point>& contour, const cv::Mat& image,
                                    const QuadFitParams& params, bool cut_open) {
  const int n = static_cast<int>(contour.size());
  if (n < 16) return std::nullopt;
  // The outline as a polygon whose straight runs are the candidates for the sides. The tolerance
  // keeps a side whole (a binarised edge wanders a pixel) and breaks a disc's arc into chords
  // much shorter than the sides.
  const float perimeter = perimeterOf(contour);
  const double tolerance = std::max(1.2, 0.012 * perimeter);
  std::vector<cv::Point> polygon;
  cv::approxPolyDP(contour, polygon, tolerance, true);
  if (polygon.size() >= 4 && polygon.size() <= 24) {
    const std::vector<int> at = contourIndices(contour, polygon);
    if (!at.empty()) {
      if (auto quad = occludedQuadFromPolygon(contour, polygon, at, perimeter, image, params))
        return quad;
    }
  }
  // A light occluder cuts the border open, and the outline runs in through the gap round the
  // code cells: its polygon has too many runs, or its longest are not the sides. The outline's
  // convex hull skips the cut (a short chord across the covered corner) and keeps the four sides.
  if (!cut_open) return std::nullopt;
  std::vector<int> hull_indices;
  cv::convexHull(contour, hull_indices, false, false);
  if (hull_indices.size() < 4) return std::nullopt;
  std::sort(hull_indices.begin(), hull_indices.end());
  std::vector<cv::Point> hull;
  for (const int i : hull_indices) hull.push_back(contour[static_cast<size_t>(i)]);
  cv::approxPolyDP(std::vector<cv::Point>(hull), polygon, std::max(1.2, 0.012 * perimeterOf(hull)),
                   true);
  if (polygon.size() < 4 || polygon.size() > 24) return std::nullopt;
  const std::vector<int> at = contourIndices(contour, polygon);
  if (at.empty()) return std::nullopt;
  return occludedQuadFromPolygon(contour, polygon, at, perimeterOf(hull), image, params);
}

}  // namespace arbci::vision
