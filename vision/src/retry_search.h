// Private: the later passes of the square search (search_passes.h) over the regions RetryRegions
// chose. Each region is thresholded again around its box: near misses with a lighter split, then
// on the unsmoothed frame; fragment groups with a lighter split still; a thin region of the
// reduced image on the full-resolution frame; and, at full resolution, whatever no retry read at
// the region's own mid-grey. New quads are added where no quad was found already.
#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/search_passes.h"
#include "quad_fit.h"
#include "retry_regions.h"
#include "run_labeling.h"
#include "tile_thresholds.h"

namespace arbci::vision {

class Undistorter;

// The frame the search works on.
struct SearchedFrame {
  const cv::Mat* gray = nullptr;       // the frame's luminance
  const cv::Mat* binarised = nullptr;  // `gray`, or its smoothed copy
  const cv::Mat* searched = nullptr;   // `binarised`, or the reduced image (`scale` 2)
  int scale = 1;
  const Undistorter* lens = nullptr;  // ideal corners of the quads found
  float min_side_px = 8.0f;           // of the frame
};

// The quads found in a frame so far: of the searched image, and those found on the frame itself
// (thin regions of a reduced image).
struct FoundQuads {
  std::vector<Quad> searched;
  std::vector<Quad> on_frame;
  // True when `p` (searched image px) lies inside a quad of the searched image.
  bool inside(cv::Point2f p) const;
};

class RetrySearch {
 public:
  // Retries `regions` in `frame` (thresholds from `adaptive`, the first pass's); `traced` are the
  // first pass's components whose outlines were fitted already (not fitted again); `params` the
  // first pass's quad fit.
  void run(const SearchedFrame& frame, AdaptiveThresholder& adaptive, const RetryRegions& regions,
           const std::vector<DarkComponent>& traced, const QuadFitParams& params,
           const SearchPasses& passes, FoundQuads& found);

 private:
  cv::Rect joinedWithOverlappingQuads(const cv::Rect& box) const;
  cv::Rect joinedWithTouchingFailures(const cv::Rect& box, int margin) const;
  bool foundInside(const cv::Rect& box) const;
  bool wasTraced(const DarkComponent& c, cv::Point origin) const;
  bool atSplit(const cv::Rect& roi, const cv::Mat& source, int split, const QuadFitParams& params);
  void atMidGrey(const cv::Rect& roi, double min_range, const QuadFitParams& params);
  bool onFrame(const cv::Rect& reduced_roi);
  template <typename Wanted>
  bool fitRegion(const cv::Rect& roi, const cv::Mat& source, const cv::Mat& limits,
                 const QuadFitParams& frame_params, Wanted wanted);
  template <typename Wanted, typename Found>
  void fitComponents(const cv::Mat& patch, cv::Point origin, const QuadFitParams& params,
                     Wanted wanted, Found found);
  bool addRetried(Quad& quad);
  cv::Point2f toReduced(cv::Point2f frame) const;

  // Set for one run().
  const SearchedFrame* frame_ = nullptr;
  AdaptiveThresholder* adaptive_ = nullptr;
  const RetryRegions* regions_ = nullptr;
  const std::vector<DarkComponent>* traced_ = nullptr;
  const SearchPasses* passes_ = nullptr;
  FoundQuads* found_ = nullptr;

  RunLabeler labels_;
  cv::Mat limits_, mid_grey_limits_;
  std::vector<cv::Point> contour_;
  std::vector<Quad> reduced_found_;  // a thin region's quads of the reduced image, kept aside
};

}  // namespace arbci::vision
