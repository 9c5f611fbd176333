// Private: where the square search looks again in a frame. The first pass's outlines that did not
// fit a quad are sorted into the regions the later passes retry (search_passes.h): near misses
// (a quadrilateral hull with dark along every side), cut corners (ringed, a corner lost), groups
// of fragments, and pairs of overlapping groups; each kind capped per frame by its settings.
#pragma once

#include <array>
#include <vector>

#include <opencv2/core/types.hpp>

#include "arbci/vision/search_passes.h"
#include "quad_fit.h"
#include "run_labeling.h"

namespace arbci::vision {

struct RetryRegion {
  cv::Rect box;         // of the searched image
  bool fragmented;      // several failed components, rather than one square-hulled outline
  bool thin = false;    // labelled again on the frame (passes.thin_on_frame)
  bool ringed = false;  // encloses a hole, as a marker's border does (decimated search only)
  bool joined = false;  // two fragment groups whose boxes overlap, tried when neither gave a quad
};

class RetryRegions {
 public:
  // A new frame, searched at `scale` (1, or 2 for the reduced image) for squares of at least
  // `min_side` searched px.
  void start(const SearchPasses& passes, int scale, float min_side);
  // An outline of the first pass that did not fit a quad (`fit`), of the frame labelled in
  // `labels`. Larger than near_misses.max_side_px, it is left alone.
  void addFailure(const DarkComponent& c, const QuadFit& fit, const RunLabeler& labels);
  // After the first pass, `found` its quads: caps the near misses and cut corners, then groups
  // the fragments (not those inside a quad found: a marker's code cells) and joins overlapping
  // groups. regions() then lists near misses and cut corners first, then the groups.
  void finish(const std::vector<Quad>& found);

  const std::vector<RetryRegion>& regions() const { return regions_; }
  // The failed outlines' boxes; a group's first member holds the whole group's box.
  const std::vector<cv::Rect>& failures() const { return failed_; }

  // A hull narrower than thin_on_frame.max_width_px (its area over its longest side) and as long
  // as its min_length_px (along a side or a diagonal: a marker skewed into a narrow rhombus has
  // short sides).
  static bool isThin(const std::array<cv::Point, 4>& hull, const SearchPasses::ThinOnFrame& thin);

 private:
  bool everySideHasDark(const std::array<cv::Point, 4>& hull, const RunLabeler& labels) const;
  bool markerSized(const cv::Rect& box) const;
  void groupFragments(const std::vector<Quad>& found);
  void joinOverlappingGroups(size_t first_group);
  static void keepLargest(std::vector<RetryRegion>& regions, size_t count);

  SearchPasses passes_;
  int scale_ = 1;
  float min_side_ = 4.0f;
  std::vector<cv::Rect> failed_;
  std::vector<int> failed_rings_;  // per failed outline (then group): how many enclose a hole
  std::vector<RetryRegion> regions_;
  std::vector<RetryRegion> cut_corners_;
  std::vector<int> group_, group_size_;
};

}  // namespace arbci::vision
