#include "retry_search.h"

#include <opencv2/core.hpp>

#include "arbci/vision/undistortion.h"
#include "contour_trace.h"
#include "quad_geometry.h"

namespace arbci::vision {

bool FoundQuads::inside(cv::Point2f p) const {
  for (const Quad& quad : searched) {
    // A quad fitted round a covered corner may be a smeared outline's guess: it does not keep a
    // retry from finding what is really there.
    if (!quad.occluded && insideConvex(quad.corners, p)) return true;
  }
  return false;
}

void RetrySearch::run(const SearchedFrame& frame, AdaptiveThresholder& adaptive,
                      const RetryRegions& regions, const std::vector<DarkComponent>& traced,
                      const QuadFitParams& params, const SearchPasses& passes, FoundQuads& found) {
  frame_ = &frame;
  adaptive_ = &adaptive;
  regions_ = &regions;
  traced_ = &traced;
  passes_ = &passes;
  found_ = &found;
  const cv::Mat& searched = *frame.searched;
  const int scale = frame.scale;
  const cv::Rect image(0, 0, searched.cols, searched.rows);
  const int margin = passes.near_misses.margin_px / scale;
  const auto [frame_darkest, frame_lightest] = adaptive.imageRange();
  const double mid_grey_min_range = passes.mid_grey.min_range * (frame_lightest - frame_darkest);
  std::vector<Quad>& quads = found.searched;
  for (const RetryRegion& region : regions.regions()) {
    if (region.joined && foundInside(region.box)) continue;
    const cv::Rect box = region.fragmented ? region.box : joinedWithOverlappingQuads(region.box);
    const cv::Rect roi = grown(box, margin) & image;
    const int split = region.fragmented ? passes.fragments.split : passes.near_misses.split;
    const size_t before = quads.size();
    const bool found_here = atSplit(roi, searched, split, params);
    // A thin region is labelled on the frame too, and its quads there replace the reduced
    // image's, whose code cells may have merged (a quad that fails to decode). One without a
    // hole (mostly letters and strokes, ten times as many) only when the reduced image gave it a
    // quad: labelling every one on the frame would cost more than it finds.
    if (region.thin && (found_here || region.ringed || region.fragmented)) {
      reduced_found_.assign(quads.begin() + static_cast<std::ptrdiff_t>(before), quads.end());
      quads.resize(before);
      if (onFrame(joinedWithTouchingFailures(region.box, margin) & image)) continue;
      quads.insert(quads.end(), reduced_found_.begin(), reduced_found_.end());
    }
    if (found_here || scale > 1) continue;
    // A thin, steeply tilted marker that smoothing erased survives in the unsmoothed frame (not
    // tried for fragment groups: in noisy frames that costs more than it finds).
    if (!region.fragmented && frame.binarised != frame.gray &&
        atSplit(roi, *frame.gray, AdaptiveThresholder::kSplit, params))
      continue;
    if (passes.mid_grey.enabled) atMidGrey(roi, mid_grey_min_range, params);
  }
}

// `box` joined with the quads found so far that it partly overlaps. A smear across a marker's
// border can cut the marker in two: one end fitted as a quad of its own (which does not decode)
// and the other a near miss; thresholded again around the near miss alone, the marker would be
// cut off at the region's edge. Only quads no larger than the box (a larger one was mostly a
// marker found beside clutter), within near_misses.max_join_growth. Not for fragment groups:
// those beside a quad were mostly a found marker's smeared surround.
cv::Rect RetrySearch::joinedWithOverlappingQuads(const cv::Rect& box) const {
  cv::Rect joined = box;
  for (const Quad& quad : found_->searched) {
    const cv::Rect outline = pixelBox(quad.corners);
    if (outline.area() <= box.area() && !(outline & box).empty()) joined |= outline;
  }
  return joined.area() > passes_->near_misses.max_join_growth * box.area() ? box : joined;
}

// `box` joined with the failed outlines and fragment groups it overlaps, grown by `margin`: a
// thin marker that the reduced image broke into pieces (a ringed piece and an open one) is
// labelled on the frame whole, not cut off at the ringed piece's end.
cv::Rect RetrySearch::joinedWithTouchingFailures(const cv::Rect& box, int margin) const {
  cv::Rect joined = box;
  for (const cv::Rect& other : regions_->failures()) {
    if (!(other & box).empty()) joined |= other;
  }
  if (joined.area() > passes_->near_misses.max_join_growth * box.area()) joined = box;
  return grown(joined, margin);
}

// True when a quad found so far has its centre inside `box` (of the searched image).
bool RetrySearch::foundInside(const cv::Rect& box) const {
  const cv::Rect2f area(box);
  for (const Quad& quad : found_->searched) {
    if (area.contains(centre(quad.corners))) return true;
  }
  return false;
}

// True when the first pass had this component (of a region at `origin`) and fitted it already:
// the same box and area are the same pixels here, whose fit would only repeat.
bool RetrySearch::wasTraced(const DarkComponent& c, cv::Point origin) const {
  for (const DarkComponent& t : *traced_) {
    if (t.area == c.area && t.min_x == c.min_x + origin.x && t.min_y == c.min_y + origin.y &&
        t.max_x == c.max_x + origin.x && t.max_y == c.max_y + origin.y)
      return true;
  }
  return false;
}

// Thresholds `roi` of `source` with edge tiles split at `split` sixteenths; adds the new quads.
bool RetrySearch::atSplit(const cv::Rect& roi, const cv::Mat& source, int split,
                          const QuadFitParams& params) {
  adaptive_->roiLimits(roi, split, limits_);
  return fitRegion(roi, source, limits_, params,
                   [&](const DarkComponent& c) { return !wasTraced(c, roi.tl()); });
}

// One threshold, halfway between the region's darkest and lightest grey, where these span at
// least `min_range` grey levels. Components the first pass fitted are fitted again here: a solid
// one was dropped there unfitted, and at this threshold it may be a marker's outline.
void RetrySearch::atMidGrey(const cv::Rect& roi, double min_range, const QuadFitParams& params) {
  const cv::Mat patch = (*frame_->searched)(roi);
  double darkest = 0.0, lightest = 0.0;
  cv::minMaxLoc(patch, &darkest, &lightest);
  if (lightest - darkest < min_range) return;
  mid_grey_limits_.create(patch.size(), CV_8UC1);
  mid_grey_limits_.setTo(cv::Scalar(0.5 * (darkest + lightest)));
  fitRegion(roi, *frame_->searched, mid_grey_limits_, params,
            [](const DarkComponent&) { return true; });
}

// Labels `roi` of `source` against `limits` (its size) and adds the quads of the components
// `wanted` accepts; true when one was added.
template <typename Wanted>
bool RetrySearch::fitRegion(const cv::Rect& roi, const cv::Mat& source, const cv::Mat& limits,
                            const QuadFitParams& frame_params, Wanted wanted) {
  QuadFitParams params = frame_params;
  params.lens = nullptr;  // region coordinates; ideal corners are computed in addRetried()
  const cv::Mat patch = source(roi);
  labels_.label(patch, limits);
  bool added = false;
  fitComponents(patch, roi.tl(), params, wanted,
                [&](Quad& quad) { added = addRetried(quad) || added; });
  return added;
}

// Adds a retried region's quad unless it lies in one found already (from the frame or an earlier
// retry). True when added.
bool RetrySearch::addRetried(Quad& quad) {
  // The region's ideal corners were computed as if it were the whole image: redo them (a reduced
  // image's are, when its quads are refined on the frame).
  const Undistorter* lens = frame_->lens;
  for (int k = 0; k < 4; ++k) {
    quad.ideal_corners[k] =
        lens && frame_->scale == 1 ? toFloat(lens->undistort(quad.corners[k])) : quad.corners[k];
  }
  if (found_->inside(centre(quad.corners))) return false;
  found_->searched.push_back(quad);
  return true;
}

// The quads of `labels_`' components in `patch` (at `origin` of its image) that are marker-sized,
// do not touch the patch's border and `wanted` accepts, their corners moved by `origin`, each
// given to `found`.
template <typename Wanted, typename Found>
void RetrySearch::fitComponents(const cv::Mat& patch, cv::Point origin, const QuadFitParams& params,
                                Wanted wanted, Found found) {
  for (const DarkComponent& c : labels_.components()) {
    const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
    if (c.touchesBorder(patch.cols, patch.rows) || std::max(w, h) < params.min_side ||
        std::min(w, h) < params.min_side * 0.5f || !wanted(c)) {
      continue;
    }
    if (!traceOuterContour(labels_, {c.first_x, c.first_y}, 4 * (w + h) + 64, contour_)) continue;
    auto quad = fitQuad(contour_, {c.first_x, c.first_y}, patch, params).quad;
    if (!quad) continue;
    const cv::Point2f offset(static_cast<float>(origin.x), static_cast<float>(origin.y));
    for (cv::Point2f& p : quad->corners) p += offset;
    found(*quad);
  }
}

// A thin region of the reduced image, labelled again on the frame (its thresholds interpolated
// from the reduced image's), where its code cells are wide enough to show. True when it found a
// quad.
bool RetrySearch::onFrame(const cv::Rect& reduced_roi) {
  const int scale = frame_->scale;
  adaptive_->roiLimits(reduced_roi, AdaptiveThresholder::kSplit, limits_, scale);
  const cv::Rect roi(reduced_roi.x * scale, reduced_roi.y * scale, reduced_roi.width * scale,
                     reduced_roi.height * scale);
  const cv::Mat patch = (*frame_->gray)(roi);
  labels_.label(patch, limits_);
  QuadFitParams params;
  params.min_side = frame_->min_side_px;
  std::vector<Quad>& on_frame = found_->on_frame;
  const size_t before = on_frame.size();
  const Undistorter* lens = frame_->lens;
  fitComponents(
      patch, roi.tl(), params, [](const DarkComponent& c) { return c.holes > 0; },
      [&](Quad& quad) {
        for (int k = 0; k < 4; ++k) {
          quad.ideal_corners[k] =
              lens ? toFloat(lens->undistort(quad.corners[k])) : quad.corners[k];
        }
        if (!found_->inside(toReduced(centre(quad.corners)))) on_frame.push_back(quad);
      });
  return on_frame.size() > before;
}

// A frame point in the reduced image: a reduced pixel's centre is the middle of the frame pixels
// it averages.
cv::Point2f RetrySearch::toReduced(cv::Point2f frame) const {
  const float s = static_cast<float>(frame_->scale), shift = 0.5f * (s - 1.0f);
  return (frame - cv::Point2f(shift, shift)) / s;
}

}  // namespace arbci::vision
