#include "arbci/vision/marker_detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>

#include <opencv2/imgproc.hpp>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "apriltag_detector.h"
#include "blurred_edges.h"
#include "code_decoder.h"
#include "contour_trace.h"
#include "dictionary_detector.h"
#include "marker_sampler.h"
#include "quad_fit.h"
#include "run_labeling.h"
#include "smoothing.h"
#include "tile_thresholds.h"

namespace arbci::vision {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kSmoothAboveNoise = 2.5;  // grey levels of estimated noise
// Near-miss components re-binarised per frame: the decimated search takes 8, those enclosing a
// hole first (by size alone, 8 lost a small marker); the full search 12 by size (hole-first, it
// read 5 fewer of the 300 frames of the head-motion sequence at 70 degrees).
constexpr size_t kMaxRetriesDecimated = 8;
constexpr size_t kMaxRetries = 12;
constexpr size_t kMaxCornerCutRetries = 2;  // the full search's rings with a corner cut off
constexpr size_t kMaxFragmentRetries = 6;   // and groups of fragments
constexpr size_t kMaxJoinedGroups = 2;      // and pairs of groups tried as one
constexpr int kMaxRetrySide = 160;          // px; larger borders are not thinned by blur
constexpr int kRetryMargin = 14;            // px around a near miss
constexpr int kFragmentGap = 4;             // px: failed components this close are one region
// A retry region joined with the pieces around it is kept to this many times its area: beyond
// that the pieces were clutter, not a marker's (joining them cost 3.8 % of noisy frames' time).
constexpr int kMaxJoinGrowth = 3;
// Sixteenths of a tile's range, lighter than the usual 7 so that more of a blurred border counts
// as dark: 9 closes a border that blur thinned; 11 joins the fragments of one that motion blur
// washed to mid-grey across its direction.
constexpr int kThinnedSplit = 9;
constexpr int kFragmentedSplit = 11;
// Reduced-image px: a quad narrower than this (its area over its longest side) is refined on the
// reduced image before the frame.
constexpr float kThinQuadWidth = 8.0f;
// Reduced-image px: a near miss narrower than this and at least this long (a marker seen nearly
// edge-on, its code cells 1 px or less) is labelled again on the frame. Shorter ones are too
// small to read edge-on, and retrying them (text, clutter) would cost more than they find. Those
// without a hole are 10 times as many: labelling each on the frame cost 4-9 % of the time, so
// they are labelled there only when the reduced image gave them a quad (2-21 per 100 frames).
constexpr float kThinOnFrameWidth = 10.0f;
constexpr float kThinOnFrameMinLength = 20.0f;
// px: a quad that does not read is read again on its blurred edges only when a corner moved this
// far onto them. The bench's smeared markers were 2-7 px off; from 1 px, a third more quads were
// read again (mostly noisy decoys) for no more markers.
constexpr float kLeastBlurredEdgeMove = 1.5f;
// A region's grey range, as a fraction of the frame's, from which it is tried at its mid-grey.
// Counted over the regions of 600 frames each of the small-marker scenes (seeds 1000-1099) and
// the default ones (10200-10299): every marker this read came from a region at 0.8 or more; from
// 0.85, a quarter of the regions are tried, for 46 of the 49 markers read from any region.
constexpr double kMidGreyMinRange = 0.85;

struct RetryRegion {
  cv::Rect box;
  bool fragmented;      // several failed components, rather than one square-hulled outline
  bool thin = false;    // labelled again on the frame (kThinOnFrameWidth)
  bool ringed = false;  // encloses a hole, as a marker's border does (decimated search only)
  bool joined = false;  // two fragment groups whose boxes overlap, tried when neither gave a quad
};

double microseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

bool isSquareKind(MarkerKind kind) {
  return kind == MarkerKind::Bch || kind == MarkerKind::Simple || kind == MarkerKind::Template;
}

bool insideConvex(const SquareCorners& quad, cv::Point2f p) {
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
float signedQuadArea(const SquareCorners& q) {
  float area = 0.0f;
  for (int k = 0; k < 4; ++k) area += q[k].x * q[(k + 1) % 4].y - q[(k + 1) % 4].x * q[k].y;
  return area * 0.5f;
}

float quadArea(const SquareCorners& q) {
  return std::abs(signedQuadArea(q));
}

float longestSide(const SquareCorners& q) {
  float longest = 0.0f;
  for (int k = 0; k < 4; ++k)
    longest = std::max(longest, static_cast<float>(cv::norm(q[(k + 1) % 4] - q[k])));
  return longest;
}

cv::Point2f centre(const SquareCorners& q) {
  return (q[0] + q[1] + q[2] + q[3]) * 0.25f;
}

// `box` grown by `margin` px on every side.
cv::Rect grown(const cv::Rect& box, int margin) {
  return {box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin};
}

// The whole pixels `q` covers: cv::boundingRect's result, without its InputArray set-up (42 ns a
// call against 12; called for every quad at every near miss, it cost 0.5 % of a frame).
cv::Rect pixelBox(const SquareCorners& q) {
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

cv::Point2f toFloat(cv::Point2d p) {
  return {static_cast<float>(p.x), static_cast<float>(p.y)};
}

void validate(const DetectorConfig& config) {
  if (isSquareKind(config.kind) && !(config.border > 0.0 && config.border <= 0.4)) {
    throw std::invalid_argument("border must be in (0, 0.4] of the marker side, got " +
                                std::to_string(config.border));
  }
  if (config.kind == MarkerKind::Template && config.templates.empty()) {
    throw std::invalid_argument("the template kind needs at least one trained pattern");
  }
  const int value = config.threshold.value;
  if (value < 0 || value > 255) {
    throw std::invalid_argument("threshold value must be 0..255, got " + std::to_string(value));
  }
  if (config.threshold.retries_per_frame < 0 || config.threshold.retries_per_frame > 10) {
    throw std::invalid_argument("threshold retries per frame must be 0..10");
  }
  if (config.min_side_px < 4) throw std::invalid_argument("min_side_px must be at least 4");
  if (config.search_decimate != 1 && config.search_decimate != 2) {
    throw std::invalid_argument("search_decimate must be 1 (full resolution) or 2, got " +
                                std::to_string(config.search_decimate));
  }
}

// Each 2x2 block of `full` averaged into one pixel of `half` (the rows' rounded average, then the
// columns'); an odd last row or column is left out.
void halve(const cv::Mat& full, cv::Mat& half) {
  half.create(full.rows / 2, full.cols / 2, CV_8UC1);
  for (int y = 0; y < half.rows; ++y) {
    const std::uint8_t* __restrict a = full.ptr<std::uint8_t>(2 * y);
    const std::uint8_t* __restrict b = full.ptr<std::uint8_t>(2 * y + 1);
    std::uint8_t* __restrict out = half.ptr<std::uint8_t>(y);
    int x = 0;
#ifdef __SSE2__
    const __m128i low_bytes = _mm_set1_epi16(0x00FF), one = _mm_set1_epi16(1);
    for (; x + 16 <= half.cols; x += 16) {
      __m128i sums[2];
      for (int part = 0; part < 2; ++part) {
        const __m128i rows =
            _mm_avg_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + 2 * x + 16 * part)),
                         _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + 2 * x + 16 * part)));
        const __m128i pairs =
            _mm_add_epi16(_mm_and_si128(rows, low_bytes), _mm_srli_epi16(rows, 8));
        sums[part] = _mm_srli_epi16(_mm_add_epi16(pairs, one), 1);
      }
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm_packus_epi16(sums[0], sums[1]));
    }
#endif
    for (; x < half.cols; ++x) {
      const int left = (a[2 * x] + b[2 * x] + 1) >> 1,
                right = (a[2 * x + 1] + b[2 * x + 1] + 1) >> 1;
      out[x] = static_cast<std::uint8_t>((left + right + 1) >> 1);
    }
  }
}

}  // namespace

struct MarkerDetector::Impl {
  DetectorConfig config;
  int dictionary = -1;                         // ArUco: OpenCV's dictionary
  std::unique_ptr<AprilTagDetector> apriltag;  // AprilTag: libapriltag
  int threshold = 100;  // global threshold carried between frames (automatic modes)
  std::mt19937 random;
  // `gray` is a read-only view: of the caller's pixels for grey input, else of `converted`.
  // `converted` and `smoothed` are written only by this detector and never shared with callers,
  // so reusing their buffers can never write into a caller's image.
  cv::Mat gray, converted, smoothed, half;
  const cv::Mat* binarised = nullptr;  // `gray` or `smoothed`
  // The image candidates are searched in: `binarised`, or `half` (search_decimate 2), whose
  // pixels are `scale` of the frame's.
  const cv::Mat* searched = nullptr;
  int scale = 1;
  TileThresholds tiles;
  AdaptiveThresholder adaptive;
  LimitRows limit_rows;
  RunLabeler labels;
  std::vector<cv::Point> contour;
  std::vector<Quad> quads;
  // Components that did not fit a quad, then grouped into marker-sized regions to retry.
  std::vector<DarkComponent> traced;  // the frame's components whose outline was fitted
  std::vector<cv::Rect> failed;
  std::vector<int> failed_rings;     // per failed component (then group): how many enclose a hole
  std::vector<RetryRegion> retries;  // square-hulled near misses first, then fragment groups
  std::vector<RetryRegion> corner_cut;  // rings whose hull is not square (full search)
  std::vector<int> group, group_size;
  RunLabeler roi_labels;
  cv::Mat roi_limits, mid_grey_limits;
  std::vector<Quad> on_frame_quads;  // found on the frame by retryOnFrame(), decoded as they are
  std::vector<Quad> reduced_found;   // a thin near miss's quads of the reduced image, kept aside
  std::vector<SquareCorners> squares, ideal_squares;
  // decode(): quads by decreasing area, the markers decoded (by quad index), their samples'
  // medians, and the quads in frame pixels.
  std::vector<size_t> order;
  std::vector<std::pair<size_t, MarkerDetection>> decoded;
  std::vector<std::pair<size_t, float>> medians;
  std::vector<Quad> frame_quads;

  explicit Impl(DetectorConfig c) : config(std::move(c)) {
    validate(config);
    if (config.kind == MarkerKind::Aruco)
      dictionary = dictionaryId(config.dictionary.empty() ? "DICT_6X6_250" : config.dictionary);
    if (config.kind == MarkerKind::AprilTag)
      apriltag = std::make_unique<AprilTagDetector>(config.dictionary, config.apriltag_refine_edges,
                                                    config.search_decimate);
    resetThreshold();
  }

  // ArUco and AprilTag markers are found by their own libraries, not by our stages.
  bool external() const { return dictionary >= 0 || apriltag != nullptr; }

  void resetThreshold() {
    threshold = config.threshold.value;
    random.seed(config.threshold.random_seed);
  }

  int randomThreshold() { return std::uniform_int_distribution<int>(10, 239)(random); }

  void binarise(StageTimes& time, DetectionResult& result, int global, double noise_sigma) {
    const auto start = Clock::now();
    if (config.threshold.mode == ThresholdMode::Adaptive) {
      int contrast = config.threshold.min_contrast;
      if (contrast <= 0) {
        // Ask for 6 sigma of the noise left in the binarised image (0.375 of it after smoothing).
        const double sigma = noise_sigma * (searched == &smoothed ? 0.375 : 1.0);
        contrast = std::max(8, static_cast<int>(std::lround(6.0 * sigma)));
      }
      adaptive.fill(*searched, contrast, tiles, TileThresholds::kTile / scale);
      result.threshold = tiles.median();
      result.threshold_mode = "adaptive (contrast >= " + std::to_string(contrast) + ")";
    } else {
      const auto& vignetting = config.threshold.mode == ThresholdMode::Adaptive
                                   ? std::nullopt
                                   : config.threshold.vignetting;
      fillGlobalThresholds(searched->size(), global, vignetting, tiles,
                           TileThresholds::kTile / scale);
      result.threshold = global;
      result.threshold_mode = toString(config.threshold.mode) + (vignetting ? " + vignetting" : "");
    }
    limit_rows.reset(tiles, searched->size());
    const auto mid = Clock::now();
    labels.label(*searched, limit_rows);
    const auto end = Clock::now();
    time.threshold += microseconds(start, mid);
    time.label += microseconds(mid, end);
  }

  void findQuads(StageTimes& time) {
    const auto start = Clock::now();
    quads.clear();
    const int width = searched->cols, height = searched->rows;
    const float min_side = std::max(4.0f, config.min_side_px / static_cast<float>(scale));
    const int min_area = std::max(12, static_cast<int>(0.2f * min_side * min_side));
    const int max_retry_side = kMaxRetrySide / scale;
    QuadFitParams params;
    params.min_side = min_side;
    // A reduced image's quads are refined on the frame, through the lens, when decoded.
    params.lens = scale == 1 ? config.lens.get() : nullptr;
    params.refine_edges = scale == 1;
    failed.clear();
    failed_rings.clear();
    retries.clear();
    corner_cut.clear();
    on_frame_quads.clear();
    traced.clear();
    const bool adaptive_mode = config.threshold.mode == ThresholdMode::Adaptive;
    int occluded_tries = 0;
    for (const DarkComponent& c : labels.components()) {
      if (c.area < min_area || c.touchesBorder(width, height)) continue;
      const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
      if (std::max(w, h) < min_side || std::min(w, h) < 3) continue;
      const int max_length = 4 * (w + h) + 64;
      traced.push_back(c);
      if (!traceOuterContour(labels, {c.first_x, c.first_y}, max_length, contour)) continue;
      // A BCH marker's outline encloses its light code cells (7 or more); a quadrilateral
      // enclosing none is a solid shape and is dropped unrefined. One that does not fit may still
      // be a marker whose border broke open.
      const bool solid = c.holes == 0 && config.kind == MarkerKind::Bch;
      QuadFitParams component_params = params;
      if (solid) {
        // Dropped whether it fits or not, so held to sharp corners: fewer go on to the line fit
        // (about 1 % of the time in A/B runs), and the markers found are the same within 3 of
        // 14,400 (seeds 1000, 7000, 9000).
        component_params.refine_edges = false;
        component_params.corner_allowance = 0.0f;
      }
      const QuadFit fit = fitQuad(contour, {c.first_x, c.first_y}, *searched, component_params);
      if (fit.quad) {
        if (!solid) quads.push_back(*fit.quad);
        continue;
      }
      if (c.holes > 0 && occluded_tries < config.occluded_corner_tries &&
          std::min(w, h) >= 2.0f * min_side) {
        // Ringed round light cells as a marker, but its outline is no quadrilateral: something
        // may cover part of it (a finger over a corner). Its sides are found from their visible
        // runs and its code read where enough cells show (BCH corrects the rest); it is still
        // retried below as any near miss, in case it was a marker's broken border instead.
        ++occluded_tries;
        if (const auto quad = fitOccludedQuad(contour, *searched, params)) quads.push_back(*quad);
      }
      if (adaptive_mode && std::max(w, h) <= max_retry_side) {
        failed.emplace_back(c.min_x, c.min_y, w, h);
        failed_rings.push_back(c.holes > 0);
        if (fit.hull_is_quadrilateral && std::min(w, h) >= min_side * 0.5f &&
            everySideHasDark(fit.hull_corners)) {
          const bool decimated = scale > 1, ringed = c.holes > 0;
          retries.push_back(
              {failed.back(), false, decimated && isThin(fit.hull_corners), decimated && ringed});
        } else if (scale == 1 && c.holes >= 2 && std::min(w, h) >= min_side) {
          // Ringed around light cells as a marker's border, but blur cut a thin corner off its
          // hull. Retried in the full search only, the largest two beside the other near misses
          // (among them, they crowded out small markers' in noise): on seeds 7000-7099 they read
          // 2 more blurred markers of 300; in the decimated search 1 more under motion blur for
          // 2 % of its time.
          corner_cut.push_back({failed.back(), false});
        }
      }
    }
    if (adaptive_mode) {
      keepLargest(retries, scale > 1 ? kMaxRetriesDecimated : kMaxRetries);
      keepLargest(corner_cut, kMaxCornerCutRetries);
      retries.insert(retries.end(), corner_cut.begin(), corner_cut.end());
      const size_t near_miss_count = retries.size();
      groupFragments(min_side);
      keepLargest(retries, near_miss_count + kMaxFragmentRetries);
      joinOverlappingGroups(near_miss_count, min_side);
      const auto retry_start = Clock::now();
      retryNearMisses(params);
      time.retry += microseconds(retry_start, Clock::now());
    }
    time.quads += microseconds(start, Clock::now()) - time.retry;
  }

  // A broken or dented marker border still runs along every side of its hull; a letter or an
  // open shape (an A's foot line, a C's mouth) leaves a side with no dark pixel at all. Looked
  // for a pixel inside each side's chord, at ten points.
  bool everySideHasDark(const std::array<cv::Point, 4>& hull) const {
    const cv::Point2f middle = (cv::Point2f(hull[0]) + cv::Point2f(hull[1]) + cv::Point2f(hull[2]) +
                                cv::Point2f(hull[3])) *
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

  // True when `p` (in the searched image's pixels) lies inside a quad found so far.
  bool insideAnyQuad(cv::Point2f p) const {
    for (const Quad& quad : quads) {
      if (insideConvex(quad.corners, p)) return true;
    }
    return false;
  }

  // A hull narrower than kThinOnFrameWidth (its area over its longest side) and as long as
  // kThinOnFrameMinLength (along a side or a diagonal: a marker skewed into a narrow rhombus has
  // short sides).
  static bool isThin(const std::array<cv::Point, 4>& hull) {
    const SquareCorners q{cv::Point2f(hull[0]), cv::Point2f(hull[1]), cv::Point2f(hull[2]),
                          cv::Point2f(hull[3])};
    const float longest = longestSide(q);
    const float length = std::max({longest, static_cast<float>(cv::norm(q[2] - q[0])),
                                   static_cast<float>(cv::norm(q[3] - q[1]))});
    return quadArea(q) < kThinOnFrameWidth * std::max(1.0f, longest) &&
           length >= kThinOnFrameMinLength;
  }

  // Keeps `count` regions from the first one not yet capped on: those marked `ringed` first (a
  // marker's border encloses a hole; a blurred line seldom does), then the largest. Noise leaves
  // many small near misses, and markers are seldom the smallest. (Fragment groups are kept by
  // size alone: ranked by their pieces' holes, they read 2 fewer markers of 300 under motion
  // blur.)
  static void keepLargest(std::vector<RetryRegion>& regions, size_t count) {
    if (regions.size() <= count) return;
    const size_t from =
        regions.empty() || !regions.back().fragmented
            ? 0
            : static_cast<size_t>(std::find_if(regions.begin(), regions.end(),
                                               [](const RetryRegion& r) { return r.fragmented; }) -
                                  regions.begin());
    std::partial_sort(regions.begin() + from, regions.begin() + count, regions.end(),
                      [](const RetryRegion& a, const RetryRegion& b) {
                        return a.ringed != b.ringed ? a.ringed : a.box.area() > b.box.area();
                      });
    regions.resize(count);
  }

  // A box a marker tilted up to ~70 degrees could fill: its longer side within kMaxRetrySide (of
  // the frame) and at most three times the shorter, the shorter at least half `min_side`.
  bool markerSized(const cv::Rect& box, float min_side) const {
    const int longer = std::max(box.width, box.height), shorter = std::min(box.width, box.height);
    return longer <= kMaxRetrySide / scale && shorter >= min_side * 0.5f && longer <= 3 * shorter;
  }

  // Motion blur washes out the border sides across its direction, leaving a marker as several
  // dark fragments: failed components within kFragmentGap of each other become one region
  // (union-find over their boxes). Regions of several fragments and of a marker's size, not
  // inside a marker already found (its code cells), are added to the retries.
  void groupFragments(float min_side) {
    const size_t n = failed.size();
    group.resize(n);
    for (size_t i = 0; i < n; ++i) group[i] = static_cast<int>(i);
    auto root = [&](int i) {
      while (group[i] != i) i = group[i] = group[group[i]];
      return i;
    };
    const int gap = std::max(2, kFragmentGap / scale);
    for (size_t i = 0; i < n; ++i) {
      const cv::Rect near = grown(failed[i], gap);
      for (size_t j = i + 1; j < n; ++j) {
        if ((near & failed[j]).empty()) continue;
        const int ri = root(static_cast<int>(i)), rj = root(static_cast<int>(j));
        if (ri != rj) group[std::max(ri, rj)] = std::min(ri, rj);
      }
    }
    group_size.assign(n, 0);
    for (size_t i = 0; i < n; ++i) {
      const int r = root(static_cast<int>(i));
      ++group_size[r];
      if (r != static_cast<int>(i)) {
        failed[r] |= failed[i];
        failed_rings[r] += failed_rings[i];
      }
    }
    for (size_t i = 0; i < n; ++i) {
      if (root(static_cast<int>(i)) != static_cast<int>(i) || group_size[i] < 2) continue;
      const cv::Rect& box = failed[i];
      if (!markerSized(box, min_side)) continue;
      const int longer = std::max(box.width, box.height), shorter = std::min(box.width, box.height);
      const cv::Point2f middle(box.x + 0.5f * box.width, box.y + 0.5f * box.height);
      const bool inside_found = insideAnyQuad(middle);
      // A thin marker broken into pieces: some of them ringed, the group's box narrow (a
      // diagonal one's box is not, and stays on the reduced image).
      const bool thin = scale > 1 && failed_rings[i] > 0 && shorter < 2 * kThinOnFrameWidth &&
                        longer >= kThinOnFrameMinLength;
      if (!inside_found) retries.push_back({box, true, thin});
    }
  }

  // A smear across a marker can leave its two ends as fragment groups of their own, whose boxes
  // overlap but whose pieces are too far apart to be grouped (seed 9928's 1280x720 marker: its
  // top and bottom border greyed out, its code's light cells between the two dark ends). Such a
  // pair is also tried as one region, after the groups themselves and only where they gave no
  // quad.
  void joinOverlappingGroups(size_t first_group, float min_side) {
    const size_t groups_end = retries.size();
    size_t added = 0;
    for (size_t i = first_group; i < groups_end && added < kMaxJoinedGroups; ++i) {
      for (size_t j = i + 1; j < groups_end && added < kMaxJoinedGroups; ++j) {
        const cv::Rect& a = retries[i].box;
        const cv::Rect& b = retries[j].box;
        if ((a & b).empty()) continue;
        const cv::Rect box = a | b;
        if (!markerSized(box, min_side)) continue;
        retries.push_back({.box = box, .fragmented = true, .joined = true});
        ++added;
      }
    }
  }

  // True when a quad found so far has its centre inside `box` (of the searched image).
  bool foundInside(const cv::Rect& box) const {
    const cv::Rect2f area(box);
    for (const Quad& quad : quads) {
      if (area.contains(centre(quad.corners))) return true;
    }
    return false;
  }

  // `box` joined with the quads found so far that it partly overlaps. A smear across a marker's
  // border can cut the marker in two: one end fitted as a quad of its own (which does not decode)
  // and the other a near miss (seed 9000's 1280x720 marker under motion+JPEG). Binarised again
  // around the near miss alone, the marker was cut off at the region's edge. Only quads no larger
  // than the box (a larger one was mostly a marker found beside clutter), within kMaxJoinGrowth.
  // Not for fragment groups: those beside a quad were mostly a found marker's
  // smeared surround, and joining them grew the retried area 5-7 % for nothing.
  cv::Rect joinedWithOverlappingQuads(const cv::Rect& box) const {
    cv::Rect joined = box;
    for (const Quad& quad : quads) {
      const cv::Rect outline = pixelBox(quad.corners);
      if (outline.area() <= box.area() && !(outline & box).empty()) joined |= outline;
    }
    return joined.area() > kMaxJoinGrowth * box.area() ? box : joined;
  }

  // `box` joined with the failed outlines and fragment groups it overlaps, grown by `margin`: a
  // thin marker that the reduced image broke into pieces (seed 9723's 14 x 78 px rhombus: a
  // ringed piece and an open one) is labelled on the frame whole, not cut off at the ringed
  // piece's end. Within kMaxJoinGrowth.
  cv::Rect joinedWithTouchingFailures(const cv::Rect& box, int margin) const {
    cv::Rect joined = box;
    for (const cv::Rect& other : failed) {
      if (!(other & box).empty()) joined |= other;
    }
    if (joined.area() > kMaxJoinGrowth * box.area()) joined = box;
    return grown(joined, margin);
  }

  // A marker whose border blur has thinned or broken at the usual threshold often closes when
  // its neighbourhood is binarised again with a lighter split; a thin, steeply tilted one that
  // smoothing has erased survives in the unsmoothed image (not tried for fragment groups: in
  // noisy frames that costs more than it finds).
  void retryNearMisses(const QuadFitParams& params) {
    const cv::Rect image(0, 0, searched->cols, searched->rows);
    const int margin = kRetryMargin / scale;
    const auto [frame_darkest, frame_lightest] = adaptive.imageRange();
    const double mid_grey_min_range = kMidGreyMinRange * (frame_lightest - frame_darkest);
    for (const RetryRegion& region : retries) {
      if (region.joined && foundInside(region.box)) continue;
      const cv::Rect box = region.fragmented ? region.box : joinedWithOverlappingQuads(region.box);
      const cv::Rect roi = grown(box, margin) & image;
      const int split = region.fragmented ? kFragmentedSplit : kThinnedSplit;
      const size_t before = quads.size();
      const bool found = retryRegion(roi, *searched, split, params);
      // A thin region is labelled on the frame too, and its quads there replace the reduced
      // image's, whose code cells may have merged (a quad that fails to decode). One without a
      // hole (mostly letters and strokes, 10 times as many) only when the reduced image gave it
      // a quad.
      if (region.thin && (found || region.ringed || region.fragmented)) {
        reduced_found.assign(quads.begin() + static_cast<std::ptrdiff_t>(before), quads.end());
        quads.resize(before);
        if (retryOnFrame(joinedWithTouchingFailures(region.box, margin) & image)) continue;
        quads.insert(quads.end(), reduced_found.begin(), reduced_found.end());
      }
      if (found || scale > 1) continue;
      if (!region.fragmented && binarised != &gray &&
          retryRegion(roi, gray, AdaptiveThresholder::kSplit, params))
        continue;
      retryAtMidGrey(roi, mid_grey_min_range, params);
    }
  }

  // The full search's last try of a region: one threshold, halfway between its darkest and
  // lightest grey, where these span at least `min_range` grey levels (nearly the frame's own: a
  // black border and a white quiet zone both there). A smear that greys a border where the frame
  // is mid-grey leaves the edge tiles' thresholds following the background, which breaks the
  // border or joins it to its surroundings; halfway between the marker's own black and white
  // still parts them. On the small-marker scenes it read 43 more of the 900 smeared markers of
  // seeds 1000-1099 (where it was found) and 34 more of the held-out 10200-10299, for 5-14 % more
  // of the full search's time. The decimated search, whose margin to its speed target is thin,
  // does not try it. Components the frame's labelling fitted are fitted again here: a solid one
  // was dropped there unfitted, and at this threshold it may be a marker's outline.
  void retryAtMidGrey(const cv::Rect& roi, double min_range, const QuadFitParams& params) {
    const cv::Mat patch = (*searched)(roi);
    double darkest = 0.0, lightest = 0.0;
    cv::minMaxLoc(patch, &darkest, &lightest);
    if (lightest - darkest < min_range) return;
    mid_grey_limits.create(patch.size(), CV_8UC1);
    mid_grey_limits.setTo(cv::Scalar(0.5 * (darkest + lightest)));
    fitRegion(roi, *searched, mid_grey_limits, params, [](const DarkComponent&) { return true; });
  }

  // True when the frame's labelling had this component (of a region at `origin`) and fitted it
  // already: the same box and area are the same pixels here, whose fit would only repeat.
  bool wasTraced(const DarkComponent& c, cv::Point origin) const {
    for (const DarkComponent& t : traced) {
      if (t.area == c.area && t.min_x == c.min_x + origin.x && t.min_y == c.min_y + origin.y &&
          t.max_x == c.max_x + origin.x && t.max_y == c.max_y + origin.y)
        return true;
    }
    return false;
  }

  // Binarises `roi` of `source` with edge tiles split at `split` sixteenths; adds the new quads.
  bool retryRegion(const cv::Rect& roi, const cv::Mat& source, int split,
                   const QuadFitParams& params) {
    adaptive.roiLimits(roi, split, roi_limits);
    return fitRegion(roi, source, roi_limits, params,
                     [&](const DarkComponent& c) { return !wasTraced(c, roi.tl()); });
  }

  // Labels `roi` of `source` against `limits` (its size) and adds the quads of the components
  // `wanted` accepts; true when one was added.
  template <typename Wanted>
  bool fitRegion(const cv::Rect& roi, const cv::Mat& source, const cv::Mat& limits,
                 const QuadFitParams& frame_params, Wanted wanted) {
    QuadFitParams params = frame_params;
    params.lens = nullptr;  // region coordinates; ideal corners are computed in addRetried()
    const cv::Mat patch = source(roi);
    roi_labels.label(patch, limits);
    bool added = false;
    fitComponents(patch, roi.tl(), params, wanted,
                  [&](Quad& quad) { added = addRetried(quad) || added; });
    return added;
  }

  // Adds a retried region's quad unless it lies in one found already (from the frame or an
  // earlier retry). True when added.
  bool addRetried(Quad& quad) {
    // The region's ideal corners were computed as if it were the whole image: redo them (a
    // reduced image's are, when its quads are refined on the frame).
    for (int k = 0; k < 4; ++k) {
      quad.ideal_corners[k] = config.lens && scale == 1
                                  ? toFloat(config.lens->undistort(quad.corners[k]))
                                  : quad.corners[k];
    }
    if (insideAnyQuad(centre(quad.corners))) return false;
    quads.push_back(quad);
    return true;
  }

  // The quads of `roi_labels`' components in `patch` (at `origin` of its image) that are
  // marker-sized, do not touch the patch's border and `wanted` accepts, their corners moved by
  // `origin`, each given to `found`.
  template <typename Wanted, typename Found>
  void fitComponents(const cv::Mat& patch, cv::Point origin, const QuadFitParams& params,
                     Wanted wanted, Found found) {
    for (const DarkComponent& c : roi_labels.components()) {
      const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
      if (c.touchesBorder(patch.cols, patch.rows) || std::max(w, h) < params.min_side ||
          std::min(w, h) < params.min_side * 0.5f || !wanted(c)) {
        continue;
      }
      if (!traceOuterContour(roi_labels, {c.first_x, c.first_y}, 4 * (w + h) + 64, contour))
        continue;
      auto quad = fitQuad(contour, {c.first_x, c.first_y}, patch, params).quad;
      if (!quad) continue;
      const cv::Point2f offset(static_cast<float>(origin.x), static_cast<float>(origin.y));
      for (cv::Point2f& p : quad->corners) p += offset;
      found(*quad);
    }
  }

  // A thin near miss of the reduced image, labelled again on the frame (its thresholds
  // interpolated from the reduced image's), where its code cells are wide enough to show. True
  // when it found a quad.
  bool retryOnFrame(const cv::Rect& reduced_roi) {
    adaptive.roiLimits(reduced_roi, AdaptiveThresholder::kSplit, roi_limits, scale);
    const cv::Rect roi(reduced_roi.x * scale, reduced_roi.y * scale, reduced_roi.width * scale,
                       reduced_roi.height * scale);
    const cv::Mat patch = gray(roi);
    roi_labels.label(patch, roi_limits);
    QuadFitParams params;
    params.min_side = config.min_side_px;
    const size_t before = on_frame_quads.size();
    fitComponents(
        patch, roi.tl(), params, [](const DarkComponent& c) { return c.holes > 0; },
        [&](Quad& quad) {
          for (int k = 0; k < 4; ++k) {
            quad.ideal_corners[k] =
                config.lens ? toFloat(config.lens->undistort(quad.corners[k])) : quad.corners[k];
          }
          if (!insideAnyQuad(toReduced(centre(quad.corners)))) on_frame_quads.push_back(quad);
        });
    return on_frame_quads.size() > before;
  }

  // A reduced image's point in frame pixels, and back: a reduced pixel's centre is the middle of
  // the frame pixels it averages.
  cv::Point2f toFrame(cv::Point2f reduced) const {
    const float s = static_cast<float>(scale), shift = 0.5f * (s - 1.0f);
    return reduced * s + cv::Point2f(shift, shift);
  }
  cv::Point2f toReduced(cv::Point2f frame) const {
    const float s = static_cast<float>(scale), shift = 0.5f * (s - 1.0f);
    return (frame - cv::Point2f(shift, shift)) / s;
  }

  std::array<cv::Point2f, 4> onFrameCoarse(const std::array<cv::Point2f, 4>& coarse) const {
    std::array<cv::Point2f, 4> corners;
    for (int k = 0; k < 4; ++k) corners[k] = toFrame(coarse[k]);
    return corners;
  }

  // A reduced image's quad in frame pixels, its sides moved onto the frame's edges, through the
  // lens. A thin quad (a steeply tilted marker) is first moved onto the reduced image's edges:
  // from its contour's lines alone the frame's edges can be out of reach (one such marker's
  // corner came out 3 px off and its pose flipped).
  std::optional<Quad> onFrame(const Quad& coarse) const {
    QuadFitParams params;
    Quad start = coarse;
    if (quadArea(coarse.corners) < kThinQuadWidth * longestSide(coarse.corners)) {
      params.min_side = 1.0f;
      if (const auto refined = refineQuad(coarse.corners, *searched, params)) start = *refined;
    }
    params.min_side = config.min_side_px;
    params.lens = config.lens.get();
    return refineQuad(onFrameCoarse(start.corners), *binarised, params);
  }

  // `image` as 8-bit luminance: itself when gray (a view; never written), else converted into
  // `converted`.
  cv::Mat luminanceOf(const cv::Mat& image, cv::Mat& converted) const {
    if (image.type() == CV_8UC1) return image;
    if (external() && (image.type() == CV_8UC3 || image.type() == CV_8UC4)) {
      // OpenCV's dictionaries and libapriltag are tuned on BT.601 grey.
      cv::cvtColor(image, converted,
                   image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
    } else {
      toLuminance(image, converted);
    }
    return converted;
  }

  // Samples with contrast and a dark border all round: a marker if its code decodes.
  // A quad fitted around a covered corner may show light there: a finger over a corner, a
  // quarter of a side across, hides an eighth of the border samples (two sides' quarter each).
  static bool hasMarkerBorder(const MarkerSamples& samples, bool occluded = false) {
    const int light_allowed =
        samples.border_samples / 10 + (occluded ? samples.border_samples / 8 : 0);
    return samples.contrast >= 8.0f && samples.border_light <= light_allowed;
  }

  // The marker that `quad`'s samples of `image` read as, its corners in the printed order;
  // without `chase`, BCH codes are not Chase-decoded.
  std::optional<MarkerDetection> read(const cv::Mat& image, const Quad& quad,
                                      const MarkerSamples& samples, bool chase = true) const {
    if (!hasMarkerBorder(samples, quad.occluded)) return std::nullopt;
    MarkerDetection marker;
    marker.kind = config.kind;
    if (config.kind == MarkerKind::Template) {
      const auto match =
          matchTemplate(sampleCodeArea(image, quad, config.border, TemplatePattern::kSize),
                        config.templates, config.template_limits);
      if (!match) return std::nullopt;
      marker.id = match->id;
      marker.orientation = match->orientation;
      marker.confidence = match->confidence;
    } else {
      const CodeReadings readings = !config.soft_decoding ? CodeReadings::Plain
                                    : chase               ? CodeReadings::SharpenedAndChase
                                                          : CodeReadings::Sharpened;
      const auto code = decodeCode(config.kind, samples, readings);
      if (!code) return std::nullopt;
      marker.id = code->id;
      marker.orientation = code->orientation;
      marker.confidence = code->confidence;
      marker.corrected_bits = code->corrected_bits;
    }
    // Printed corner k (TL, TR, BR, BL) is quad corner (k + 4 - orientation) mod 4.
    for (int k = 0; k < 4; ++k) {
      marker.corners[k] = quad.corners[(k + 4 - marker.orientation) % 4];
      marker.ideal_corners[k] = quad.ideal_corners[(k + 4 - marker.orientation) % 4];
    }
    return marker;
  }

  // A quad with a marker's border whose code does not decode, its sides moved onto
  // motion-blurred edges (placeOnBlurredEdges()) and read again, without Chase decoding; then
  // `quad` and `samples` are the moved quad's. (On the bench's motion-blurred frames no quad that
  // failed for want of contrast or a dark border read after the move. Chase decoding there read
  // a quarter more markers, but also two decoys of marker-free frames as markers: a second
  // reading of every failing decoy doubles its chances.)
  std::optional<MarkerDetection> readOnBlurredEdges(Quad& quad, MarkerSamples& samples) const {
    if (!hasMarkerBorder(samples)) return std::nullopt;
    QuadFitParams params;
    params.min_side = config.min_side_px;
    params.lens = config.lens.get();
    const auto placed = placeOnBlurredEdges(quad, gray, params);
    if (!placed) return std::nullopt;
    // Sides that hardly moved read as before.
    float moved = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const cv::Point2f d = placed->corners[k] - quad.corners[k];
      moved = std::max(moved, d.dot(d));
    }
    if (moved < kLeastBlurredEdgeMove * kLeastBlurredEdgeMove) return std::nullopt;
    MarkerSamples placed_samples = sampleMarker(gray, *placed, config.border);
    auto marker = read(gray, *placed, placed_samples, /*chase=*/false);
    if (marker) {
      quad = *placed;
      samples = placed_samples;
    }
    return marker;
  }

  // Decodes every quad, largest first (a reduced image's refined on the frame first); returns
  // the samples' extremes and the first marker's median (in the frame's order) for the automatic
  // thresholds. Leaves `quads` the frame's quads that were looked at.
  void decode(StageTimes& time, std::vector<MarkerDetection>& markers, float& lowest,
              float& highest, float& marker_median) {
    const auto start = Clock::now();
    double refining = 0.0;
    // A quad inside a marker already decoded would be dropped as nested (code cells): it is not
    // refined or decoded, except where every candidate's samples set the next threshold.
    const bool skip_nested = config.threshold.mode != ThresholdMode::AutoMidrange;
    // Quads of the searched image, then those already on the frame (retryOnFrame()).
    const size_t searched_count = quads.size();
    const float frame_area_per_searched = static_cast<float>(scale * scale);
    auto frameArea = [&](size_t i) {
      return i < searched_count ? quadArea(quads[i].corners) * frame_area_per_searched
                                : quadArea(on_frame_quads[i - searched_count].corners);
    };
    order.resize(searched_count + on_frame_quads.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return frameArea(a) > frameArea(b); });
    decoded.clear();
    frame_quads.clear();
    for (const size_t index : order) {
      const bool on_frame = index >= searched_count;
      Quad quad = on_frame ? on_frame_quads[index - searched_count] : quads[index];
      if (skip_nested) {
        const cv::Point2f middle = on_frame ? centre(quad.corners) : toFrame(centre(quad.corners));
        bool nested = false;
        for (size_t m = 0; m < decoded.size() && !nested; ++m)
          nested = insideConvex(decoded[m].second.corners, middle);
        if (nested) continue;
      }
      if (scale > 1 && !on_frame) {
        // A flat code area is no BCH marker whoever refines it: not worth refining.
        if (config.kind == MarkerKind::Bch &&
            hasFlatCodeArea(gray, onFrameCoarse(quad.corners), config.border))
          continue;
        const auto refine_start = Clock::now();
        const auto refined = onFrame(quad);
        refining += microseconds(refine_start, Clock::now());
        if (!refined) continue;
        quad = *refined;
      }
      MarkerSamples samples = sampleMarker(gray, quad, config.border);
      lowest = std::min(lowest, samples.lowest);
      highest = std::max(highest, samples.highest);
      auto marker = read(gray, quad, samples);
      if (!marker) marker = readOnBlurredEdges(quad, samples);
      frame_quads.push_back(quad);
      if (!marker) continue;
      decoded.emplace_back(index, *marker);
      medians.emplace_back(index, samples.median);
    }
    // The frame's (raster) order, as found.
    std::sort(decoded.begin(), decoded.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [index, marker] : decoded) markers.push_back(marker);
    if (!medians.empty()) {
      marker_median = std::min_element(medians.begin(), medians.end())->second;
      medians.clear();
    }
    quads.swap(frame_quads);
    time.decode += microseconds(start, Clock::now()) - refining;
    time.refine += refining;
  }

  // A square inside a larger decoded marker (e.g. a block of code cells) is not a marker.
  static void dropNested(std::vector<MarkerDetection>& markers) {
    std::vector<MarkerDetection> kept;
    for (const MarkerDetection& m : markers) {
      bool nested = false;
      for (const MarkerDetection& other : markers) {
        if (&other != &m && quadArea(other.corners) > quadArea(m.corners) &&
            insideConvex(other.corners, centre(m.corners))) {
          nested = true;
          break;
        }
      }
      if (!nested) kept.push_back(m);
    }
    markers.swap(kept);
  }

  DetectionResult detectSquares(StageTimes& time) {
    DetectionResult result;
    auto start = Clock::now();
    scale = config.search_decimate;
    double noise_sigma = 0.0;  // of the image searched, before any smoothing
    if (scale == 2) {
      // A 2x2 average is itself a smoothing (white noise halved): the frame is not smoothed.
      halve(gray, half);
      noise_sigma = estimateNoiseSigma(half);
      binarised = &gray;
      searched = &half;
    } else {
      // Smoothing suppresses sensor noise but softens small markers further: by default only a
      // visibly noisy or a JPEG-compressed frame is smoothed.
      noise_sigma = estimateNoiseSigma(gray);
      const bool smooth = config.smoothing == Smoothing::Always ||
                          (config.smoothing == Smoothing::Auto &&
                           (noise_sigma >= kSmoothAboveNoise || looksBlockCompressed(gray)));
      if (smooth) smoothBinomial3(gray, smoothed);
      binarised = smooth ? &smoothed : &gray;
      searched = binarised;
    }
    time.smooth = microseconds(start, Clock::now());

    const ThresholdMode mode = config.threshold.mode;
    const bool automatic = mode == ThresholdMode::AutoMedian || mode == ThresholdMode::AutoMidrange;
    const int attempts = automatic ? 1 + config.threshold.retries_per_frame : 1;
    for (int attempt = 0; attempt < attempts; ++attempt) {
      const int global = mode == ThresholdMode::Constant ? config.threshold.value : threshold;
      binarise(time, result, global, noise_sigma);
      findQuads(time);
      float lowest = 255.0f, highest = 0.0f, marker_median = -1.0f;
      result.markers.clear();
      decode(time, result.markers, lowest, highest, marker_median);
      result.candidates = static_cast<int>(quads.size());
      result.threshold_attempts = attempt + 1;
      if (!automatic) break;
      // ARToolKitPlus: midrange of all candidates' code samples; the original system: the median
      // of the last seen marker's pixels. While nothing is found, a random threshold.
      const bool found =
          mode == ThresholdMode::AutoMidrange ? !quads.empty() : !result.markers.empty();
      if (found) {
        threshold = mode == ThresholdMode::AutoMidrange
                        ? static_cast<int>(std::lround((lowest + highest) * 0.5f))
                        : static_cast<int>(std::lround(marker_median));
        threshold = std::clamp(threshold, 0, 255);
        break;
      }
      threshold = randomThreshold();
      if (attempt + 1 < attempts) result.threshold_mode += ", retry";
    }
    dropNested(result.markers);
    if (binarised == &smoothed) result.threshold_mode += ", smoothed frame";
    squares.clear();
    ideal_squares.clear();
    for (const Quad& quad : quads) {
      squares.push_back(quad.corners);
      ideal_squares.push_back(quad.ideal_corners);
    }
    return result;
  }

  // Detection on `gray`, its conversion from the caller's image timed from `start`.
  DetectionResult runAfterConversion(Clock::time_point start) {
    const double convert = microseconds(start, Clock::now());
    DetectionResult result = run();
    result.timing.convert = convert;
    result.timing.total += convert;
    return result;
  }

  DetectionResult run() {
    const auto start = Clock::now();
    StageTimes time;
    DetectionResult result;
    squares.clear();
    ideal_squares.clear();
    if (!gray.empty() && config.lens && gray.size() != config.lens->camera().image_size) {
      const cv::Size lens = config.lens->camera().image_size;
      throw std::invalid_argument("frames are " + std::to_string(gray.cols) + "x" +
                                  std::to_string(gray.rows) + " but the lens model (" +
                                  config.lens->camera().source + ") is for " +
                                  std::to_string(lens.width) + "x" + std::to_string(lens.height) +
                                  "; scale the camera model to the frame size");
    }
    if (gray.empty() || gray.cols < 3 || gray.rows < 3) {
      result.threshold = threshold;
      result.threshold_mode = "empty image";
    } else if (external()) {
      const auto decode_start = Clock::now();
      result.markers = apriltag ? apriltag->detect(gray)
                                : detectDictionaryMarkers(gray, dictionary, config.kind);
      for (MarkerDetection& m : result.markers) {
        for (int k = 0; k < 4; ++k) {
          m.ideal_corners[k] =
              config.lens ? toFloat(config.lens->undistort(m.corners[k])) : m.corners[k];
        }
      }
      time.decode = microseconds(decode_start, Clock::now());
      // Each library thresholds the frame itself: AprilTag by its own adaptive threshold, ArUco
      // by OpenCV's adaptive one.
      result.threshold_mode = apriltag ? "libapriltag's own" : "opencv adaptive";
    } else {
      result = detectSquares(time);
    }
    time.total = microseconds(start, Clock::now());
    // What no stage timed (bookkeeping between them), so that the parts add up to the total.
    double timed = 0.0;
    for (const auto& entry : kStageParts) timed += time.*entry.second;
    time.other = std::max(0.0, time.total - timed);
    time.total = timed + time.other;
    result.timing = time;
    return result;
  }
};

MarkerDetector::MarkerDetector(DetectorConfig config)
    : impl_(std::make_unique<Impl>(std::move(config))) {}
MarkerDetector::~MarkerDetector() = default;
MarkerDetector::MarkerDetector(MarkerDetector&&) noexcept = default;
MarkerDetector& MarkerDetector::operator=(MarkerDetector&&) noexcept = default;

DetectionResult MarkerDetector::detect(const cv::Mat& image) {
  const auto start = Clock::now();
  impl_->gray = impl_->luminanceOf(image, impl_->converted);
  return impl_->runAfterConversion(start);
}

DetectionResult MarkerDetector::detect(const ImageView& image) {
  const auto start = Clock::now();
  toLuminance(image, impl_->converted);
  impl_->gray = impl_->converted;
  return impl_->runAfterConversion(start);
}

std::optional<MarkerDetection> MarkerDetector::readAt(const cv::Mat& image,
                                                      const SquareCorners& corners) const {
  const Impl& impl = *impl_;
  if (!isSquareKind(impl.config.kind)) {
    throw std::invalid_argument(
        "MarkerDetector::readAt reads ARToolKitPlus-style markers (BCH, simple, template); this "
        "detector finds ArUco or AprilTag markers through their own libraries");
  }
  if (image.empty()) return std::nullopt;
  // Its own conversion: the last frame's images (lastGrayImage() and the rest) stay as they were.
  cv::Mat converted;
  const cv::Mat gray = impl.luminanceOf(image, converted);
  Quad quad;
  quad.corners = corners;
  // Clockwise on screen, as the search gives them: a mirrored grid would read another code.
  if (signedQuadArea(corners) < 0.0f) std::swap(quad.corners[1], quad.corners[3]);
  for (int k = 0; k < 4; ++k) {
    quad.ideal_corners[k] =
        impl.config.lens ? toFloat(impl.config.lens->undistort(quad.corners[k])) : quad.corners[k];
  }
  return impl.read(gray, quad, sampleMarker(gray, quad, impl.config.border));
}

const DetectorConfig& MarkerDetector::config() const {
  return impl_->config;
}

void MarkerDetector::setThreshold(const ThresholdSettings& settings) {
  DetectorConfig changed = impl_->config;
  changed.threshold = settings;
  validate(changed);
  impl_->config.threshold = settings;
  impl_->resetThreshold();
}

int MarkerDetector::currentThreshold() const {
  return impl_->threshold;
}

const std::vector<SquareCorners>& MarkerDetector::lastSquares() const {
  return impl_->squares;
}
const std::vector<SquareCorners>& MarkerDetector::lastIdealSquares() const {
  return impl_->ideal_squares;
}

cv::Mat MarkerDetector::lastBinaryImage() const {
  const cv::Mat& gray = impl_->gray;
  cv::Mat binary(gray.rows, gray.cols, CV_8UC1, cv::Scalar(0));
  const int s = impl_->scale;  // the labels are of the image searched, `s` times smaller
  if (impl_->external() || gray.empty() || impl_->labels.maskStride() != gray.cols / s + 2)
    return binary;
  for (int y = 0; y < gray.rows / s * s; ++y) {
    std::uint8_t* row = binary.ptr<std::uint8_t>(y);
    for (int x = 0; x < gray.cols / s * s; ++x) row[x] = impl_->labels.dark(x / s, y / s) ? 255 : 0;
  }
  return binary;
}

const cv::Mat& MarkerDetector::lastGrayImage() const {
  return impl_->gray;
}

}  // namespace arbci::vision
