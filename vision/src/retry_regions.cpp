#include "retry_regions.h"

#include <algorithm>
#include <cmath>

#include "quad_geometry.h"

namespace arbci::vision {

void RetryRegions::start(const SearchPasses& passes, int scale, float min_side) {
  passes_ = passes;
  scale_ = scale;
  min_side_ = min_side;
  failed_.clear();
  failed_rings_.clear();
  regions_.clear();
  cut_corners_.clear();
}

void RetryRegions::addFailure(const DarkComponent& c, const QuadFit& fit,
                              const RunLabeler& labels) {
  const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
  if (std::max(w, h) > passes_.near_misses.max_side_px / scale_) return;
  failed_.emplace_back(c.min_x, c.min_y, w, h);
  failed_rings_.push_back(c.holes > 0);
  if (fit.hull_is_quadrilateral && std::min(w, h) >= min_side_ * 0.5f &&
      everySideHasDark(fit.hull_corners, labels)) {
    if (!passes_.near_misses.enabled) return;
    const bool decimated = scale_ > 1, ringed = c.holes > 0;
    regions_.push_back({failed_.back(), false,
                        decimated && passes_.thin_on_frame.enabled &&
                            isThin(fit.hull_corners, passes_.thin_on_frame),
                        decimated && ringed});
  } else if (scale_ == 1 && c.holes >= 2 && std::min(w, h) >= min_side_ &&
             passes_.cut_corners.enabled) {
    // Ringed around light cells as a marker's border, but blur cut a thin corner off its hull.
    // Only the largest few, beside the other near misses: more crowded out small markers' near
    // misses in noisy frames. The decimated search, whose margin to its speed target is thin,
    // does not take them.
    cut_corners_.push_back({failed_.back(), false});
  }
}

void RetryRegions::finish(const std::vector<Quad>& found) {
  keepLargest(regions_, static_cast<size_t>(scale_ > 1 ? passes_.near_misses.max_regions_decimated
                                                       : passes_.near_misses.max_regions));
  keepLargest(cut_corners_, static_cast<size_t>(passes_.cut_corners.max_regions));
  regions_.insert(regions_.end(), cut_corners_.begin(), cut_corners_.end());
  if (!passes_.fragments.enabled) return;
  const size_t near_miss_count = regions_.size();
  groupFragments(found);
  keepLargest(regions_, near_miss_count + static_cast<size_t>(passes_.fragments.max_groups));
  joinOverlappingGroups(near_miss_count);
}

// A broken or dented marker border still runs along every side of its hull; a letter or an open
// shape (an A's foot line, a C's mouth) leaves a side with no dark pixel at all. Looked for a
// pixel inside each side's chord, at ten points.
bool RetryRegions::everySideHasDark(const std::array<cv::Point, 4>& hull,
                                    const RunLabeler& labels) const {
  const cv::Point2f middle =
      (cv::Point2f(hull[0]) + cv::Point2f(hull[1]) + cv::Point2f(hull[2]) + cv::Point2f(hull[3])) *
      0.25f;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2f a(hull[k]), b(hull[(k + 1) % 4]);
    bool dark = false;
    for (int j = 1; j <= 10 && !dark; ++j) {
      const cv::Point2f p = a + (b - a) * (static_cast<float>(j) / 11.0f);
      const cv::Point2f inward = middle - p;
      const cv::Point2f q = p + inward / std::max(1.0f, std::sqrt(inward.dot(inward)));
      dark = labels.dark(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)));
    }
    if (!dark) return false;
  }
  return true;
}

bool RetryRegions::isThin(const std::array<cv::Point, 4>& hull,
                          const SearchPasses::ThinOnFrame& thin) {
  const QuadCorners q{cv::Point2f(hull[0]), cv::Point2f(hull[1]), cv::Point2f(hull[2]),
                      cv::Point2f(hull[3])};
  const float longest = longestSide(q);
  const float length = std::max({longest, static_cast<float>(cv::norm(q[2] - q[0])),
                                 static_cast<float>(cv::norm(q[3] - q[1]))});
  return quadArea(q) < static_cast<float>(thin.max_width_px) * std::max(1.0f, longest) &&
         length >= static_cast<float>(thin.min_length_px);
}

// Keeps `count` regions from the first one not yet capped on: those marked `ringed` first (a
// marker's border encloses a hole; a blurred line seldom does), then the largest. Noise leaves
// many small near misses, and markers are seldom the smallest. (Fragment groups are kept by size
// alone: ranked by their pieces' holes, fewer motion-blurred markers were read.)
void RetryRegions::keepLargest(std::vector<RetryRegion>& regions, size_t count) {
  if (regions.size() <= count) return;
  const size_t from =
      regions.empty() || !regions.back().fragmented
          ? 0
          : static_cast<size_t>(std::find_if(regions.begin(), regions.end(),
                                             [](const RetryRegion& r) { return r.fragmented; }) -
                                regions.begin());
  std::partial_sort(regions.begin() + static_cast<std::ptrdiff_t>(from),
                    regions.begin() + static_cast<std::ptrdiff_t>(count), regions.end(),
                    [](const RetryRegion& a, const RetryRegion& b) {
                      return a.ringed != b.ringed ? a.ringed : a.box.area() > b.box.area();
                    });
  regions.resize(count);
}

// A box a marker tilted up to ~70 degrees could fill: its longer side within max_side_px (of the
// frame) and at most three times the shorter, the shorter at least half the least side.
bool RetryRegions::markerSized(const cv::Rect& box) const {
  const int longer = std::max(box.width, box.height), shorter = std::min(box.width, box.height);
  return longer <= passes_.near_misses.max_side_px / scale_ && shorter >= min_side_ * 0.5f &&
         longer <= 3 * shorter;
}

// Failed outlines within fragments.gap_px of each other become one region (union-find over their
// boxes). Regions of several fragments and of a marker's size, not inside a marker found already
// (its code cells), are added.
void RetryRegions::groupFragments(const std::vector<Quad>& found) {
  const size_t n = failed_.size();
  group_.resize(n);
  for (size_t i = 0; i < n; ++i) group_[i] = static_cast<int>(i);
  auto root = [&](int i) {
    while (group_[i] != i) i = group_[i] = group_[group_[i]];
    return i;
  };
  const int gap = std::max(2, passes_.fragments.gap_px / scale_);
  for (size_t i = 0; i < n; ++i) {
    const cv::Rect near = grown(failed_[i], gap);
    for (size_t j = i + 1; j < n; ++j) {
      if ((near & failed_[j]).empty()) continue;
      const int ri = root(static_cast<int>(i)), rj = root(static_cast<int>(j));
      if (ri != rj) group_[std::max(ri, rj)] = std::min(ri, rj);
    }
  }
  group_size_.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const int r = root(static_cast<int>(i));
    ++group_size_[r];
    if (r != static_cast<int>(i)) {
      failed_[r] |= failed_[i];
      failed_rings_[r] += failed_rings_[i];
    }
  }
  const SearchPasses::ThinOnFrame& thin_on_frame = passes_.thin_on_frame;
  for (size_t i = 0; i < n; ++i) {
    if (root(static_cast<int>(i)) != static_cast<int>(i) || group_size_[i] < 2) continue;
    const cv::Rect& box = failed_[i];
    if (!markerSized(box)) continue;
    const int longer = std::max(box.width, box.height), shorter = std::min(box.width, box.height);
    const cv::Point2f middle(box.x + 0.5f * box.width, box.y + 0.5f * box.height);
    bool inside_found = false;
    for (const Quad& quad : found)
      inside_found = inside_found || (!quad.occluded && insideConvex(quad.corners, middle));
    // A thin marker broken into pieces: some of them ringed, the group's box narrow (a diagonal
    // one's box is not, and stays on the reduced image).
    const bool thin = scale_ > 1 && thin_on_frame.enabled && failed_rings_[i] > 0 &&
                      shorter < 2 * static_cast<float>(thin_on_frame.max_width_px) &&
                      longer >= static_cast<float>(thin_on_frame.min_length_px);
    if (!inside_found) regions_.push_back({box, true, thin});
  }
}

// A smear across a marker can leave its two ends as fragment groups of their own, whose boxes
// overlap but whose pieces are too far apart to be grouped. Such a pair is also tried as one
// region, after the groups themselves and only where they gave no quad.
void RetryRegions::joinOverlappingGroups(size_t first_group) {
  const size_t groups_end = regions_.size();
  const size_t most = static_cast<size_t>(passes_.fragments.max_joined_pairs);
  size_t added = 0;
  for (size_t i = first_group; i < groups_end && added < most; ++i) {
    for (size_t j = i + 1; j < groups_end && added < most; ++j) {
      const cv::Rect& a = regions_[i].box;
      const cv::Rect& b = regions_[j].box;
      if ((a & b).empty()) continue;
      const cv::Rect box = a | b;
      if (!markerSized(box)) continue;
      regions_.push_back({.box = box, .fragmented = true, .joined = true});
      ++added;
    }
  }
}

}  // namespace arbci::vision
