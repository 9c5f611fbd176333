#include "arbci/vision/marker_detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_family.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "blurred_edges.h"
#include "contour_trace.h"
#include "edge_quads.h"
#include "marker_sampler.h"
#include "quad_fit.h"
#include "quad_geometry.h"
#include "quad_reader.h"
#include "retry_regions.h"
#include "retry_search.h"
#include "run_labeling.h"
#include "smoothing.h"
#include "tile_thresholds.h"

namespace arbci::vision {
namespace {

using Clock = std::chrono::steady_clock;

double microseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

void validate(const DetectorConfig& config, const MarkerFamily& family) {
  if (family.squares() && !(config.border > 0.0 && config.border <= 0.4)) {
    throw std::invalid_argument("border must be in (0, 0.4] of the marker side, got " +
                                std::to_string(config.border));
  }
  if (family.templates && config.templates.empty()) {
    throw std::invalid_argument("the " + toString(config.kind) +
                                " kind needs at least one trained pattern");
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
  const MarkerFamily& family;
  std::optional<WholeImageSearch> whole_image;  // a family another library finds
  int threshold = 100;  // global threshold carried between frames (automatic modes)
  std::mt19937 random;
  // `gray` is a read-only view: of the caller's pixels for grey input, else of `converted`.
  // `converted` and `smoothed` are written only by this detector and never shared with callers,
  // so reusing their buffers can never write into a caller's image.
  cv::Mat gray, converted, smoothed, half, edges_image;
  const cv::Mat* binarised = nullptr;  // `gray` or `smoothed`
  // The image candidates are searched in: `binarised`, or `half` (search_decimate 2), whose
  // pixels are `scale` of the frame's.
  const cv::Mat* searched = nullptr;
  // Whether this frame's markers are placed on its own edges (passes.place_on_frame): it was
  // smoothed other than for its noise.
  bool place_on_frame = false;
  int scale = 1;
  TileThresholds tiles;
  AdaptiveThresholder adaptive;
  LimitRows limit_rows;
  RunLabeler labels;  // the first pass's
  std::vector<cv::Point> contour, hull;
  // The quads found: of the searched image, and on the frame itself (thin regions of a reduced
  // image), decoded as they are.
  FoundQuads found;
  std::vector<DarkComponent> traced;  // the first pass's components whose outline was fitted
  RetryRegions retry_regions;         // where the later passes look again
  // Searched px: the first pass's dark components no quad came of (a marker merged with a hand
  // or with the background has no outline of its own), where the edge pass looks when no id is
  // expected.
  std::vector<cv::Rect> hiding;
  RetrySearch retry_search;
  std::vector<SquareCorners> squares, ideal_squares;
  // decode(): quads by decreasing area, the markers decoded (by quad index), their samples'
  // medians, and the quads in frame pixels.
  std::vector<size_t> order;
  std::vector<std::pair<size_t, MarkerDetection>> decoded;
  std::vector<std::pair<size_t, float>> medians;
  std::vector<Quad> frame_quads;

  explicit Impl(DetectorConfig c) : config(std::move(c)), family(familyOf(config.kind)) {
    validate(config, family);
    if (family.whole_image) whole_image = family.whole_image(config);
    resetThreshold();
  }

  // ArUco and AprilTag markers are found by their own libraries, not by our stages.
  bool external() const { return whole_image.has_value(); }

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

  // A component enclosing no light region that may be a marker whose border a light occluder cut
  // open (search_passes.h). The outline and the box are checked first: most failed outlines are
  // blobs and smears, and need no hull.
  bool cutOpen(const DarkComponent& c, const std::vector<cv::Point>& outline) {
    const SearchPasses::OccludedCorners& p = config.passes.occluded_corners;
    const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
    if (static_cast<double>(outline.size()) < p.cut_open_outline * 2.0 * (w + h)) return false;
    if (c.area >= p.cut_open_fill * (static_cast<double>(w) * h)) return false;
    cv::convexHull(outline, hull);
    return c.area < p.cut_open_fill * cv::contourArea(hull);
  }

  // The first pass: a quad fitted to the outline of every dark component of a marker's size, or,
  // for one ringed round light cells whose outline is no quadrilateral, to its visible sides
  // (passes.occluded_corners). With adaptive thresholds, the outlines that did not fit are then
  // searched again where they nearly were markers (the later passes, retry_search.h).
  void findQuads(StageTimes& time) {
    const auto start = Clock::now();
    std::vector<Quad>& quads = found.searched;
    quads.clear();
    found.on_frame.clear();
    traced.clear();
    hiding.clear();
    const int width = searched->cols, height = searched->rows;
    const float min_side = std::max(4.0f, config.min_side_px / static_cast<float>(scale));
    const int min_area = std::max(12, static_cast<int>(0.2f * min_side * min_side));
    QuadFitParams params;
    params.min_side = min_side;
    // A reduced image's quads are refined on the frame, through the lens, when decoded.
    params.lens = scale == 1 ? config.lens.get() : nullptr;
    params.refine_edges = scale == 1;
    const bool adaptive_mode = config.threshold.mode == ThresholdMode::Adaptive;
    retry_regions.start(config.passes, scale, min_side);
    const SearchPasses::OccludedCorners& occluded = config.passes.occluded_corners;
    int occluded_tries = 0;
    for (const DarkComponent& c : labels.components()) {
      if (c.area < min_area) continue;
      const int w = c.max_x - c.min_x + 1, h = c.max_y - c.min_y + 1;
      if (std::max(w, h) < min_side || std::min(w, h) < 3) continue;
      const cv::Rect box(c.min_x, c.min_y, w, h);
      if (c.touchesBorder(width, height)) {
        // Enclosing light regions, it may hold a marker joined to what runs off the frame (a
        // sleeve, a dark background).
        if (c.holes > 0) hiding.emplace_back(c.min_x, c.min_y, w, h);
        continue;
      }
      const int max_length = 4 * (w + h) + 64;
      traced.push_back(c);
      if (!traceOuterContour(labels, {c.first_x, c.first_y}, max_length, contour)) continue;
      // A code whose every id has light cells (BCH: 7 or more): an outline that encloses none
      // is a solid shape and is dropped unrefined. One that does not fit may still
      // be a marker whose border broke open.
      const bool solid = c.holes == 0 && family.code && family.code->min_light_cells > 0;
      QuadFitParams component_params = params;
      if (solid) {
        // Dropped whether it fits or not, so held to sharp corners: fewer go on to the line fit,
        // for the same markers found.
        component_params.refine_edges = false;
        component_params.corner_allowance = 0.0f;
      }
      const QuadFit fit = fitQuad(contour, {c.first_x, c.first_y}, *searched, component_params);
      if (fit.quad) {
        if (!solid) quads.push_back(*fit.quad);
        continue;
      }
      hiding.push_back(box);
      if (occluded.enabled && occluded_tries < occluded.max_tries &&
          std::min(w, h) >= 2.0f * min_side && (c.holes > 0 || cutOpen(c, contour))) {
        // It is still retried below as any near miss, in case it was a marker's broken border
        // instead.
        ++occluded_tries;
        if (const auto quad = fitOccludedQuad(contour, *searched, params, c.holes == 0))
          quads.push_back(*quad);
      }
      if (adaptive_mode) retry_regions.addFailure(c, fit, labels);
    }
    if (adaptive_mode) {
      retry_regions.finish(quads);
      const auto retry_start = Clock::now();
      const SearchedFrame frame{&gray, binarised,         searched,
                                scale, config.lens.get(), config.min_side_px};
      retry_search.run(frame, adaptive, retry_regions, traced, params, config.passes, found);
      time.retry += microseconds(retry_start, Clock::now());
    }
    time.quads += microseconds(start, Clock::now()) - time.retry;
  }

  // passes.edge_segments, after the outline search's quads were decoded: as the other later
  // passes, with adaptive thresholds only (a constant or automatic threshold is the
  // experimenter's choice of what counts as dark). Where the caller said which ids to expect,
  // over the whole frame and only when one of them was not read (a tracked marker may vanish
  // anywhere); otherwise only where a marker may hide (hidingPlaces): a frame whose candidates
  // all decoded pays nothing for it.
  void searchEdges(StageTimes& time, std::vector<MarkerDetection>& markers) {
    const SearchPasses::EdgeSegments& pass = config.passes.edge_segments;
    if (config.threshold.mode != ThresholdMode::Adaptive || !pass.enabled || pass.max_quads <= 0)
      return;
    std::vector<cv::Rect> regions;  // empty: the whole frame
    if (!config.expected_ids.empty()) {
      std::set<int> missing = config.expected_ids;
      for (const MarkerDetection& m : markers) missing.erase(m.id);
      if (missing.empty()) return;
    } else {
      regions = hidingPlaces(markers);
      if (regions.empty()) return;
    }
    const auto start = Clock::now();
    std::vector<Quad> first;
    first.swap(found.searched);  // the frame's quads already looked at
    found.on_frame.clear();
    QuadFitParams params;
    params.min_side = std::max(4.0f, config.min_side_px / static_cast<float>(scale));
    params.lens = scale == 1 ? config.lens.get() : nullptr;
    addEdgeSegmentQuads(params, markers, first, regions);
    time.edges += microseconds(start, Clock::now());
    std::vector<MarkerDetection> more;
    float lowest = 255.0f, highest = 0.0f, median = -1.0f;
    decode(time, more, lowest, highest, median);
    for (const MarkerDetection& m : more) markers.push_back(m);
    first.insert(first.end(), found.searched.begin(), found.searched.end());
    found.searched.swap(first);
  }

  // Searched px: the dark components no quad came of, and the quads that did not decode, each
  // widened by a quarter of its size (a covered corner may reach past what stayed dark), those
  // inside a marker read (its code cells) left out, overlapping ones merged. Covering more than
  // half the image, the whole image (one pass costs less than many).
  std::vector<cv::Rect> hidingPlaces(const std::vector<MarkerDetection>& markers) const {
    std::vector<cv::Rect> boxes = hiding;
    // decode() leaves the quads looked at in frame pixels.
    for (const Quad& q : found.searched) {
      bool read = false;
      for (const MarkerDetection& m : markers)
        read = read || insideConvex(m.corners, centre(q.corners));
      if (read) continue;
      const cv::Rect on_frame =
          cv::boundingRect(std::vector<cv::Point2f>(q.corners.begin(), q.corners.end()));
      boxes.emplace_back(on_frame.x / scale, on_frame.y / scale, on_frame.width / scale + 1,
                         on_frame.height / scale + 1);
    }
    const cv::Rect image(0, 0, searched->cols, searched->rows);
    std::vector<cv::Rect> regions;
    for (const cv::Rect& b : boxes) {
      // Inside a marker read (its code cells), or around one (the dark that surrounds it): where
      // the marker is, no other can be.
      bool at_marker = false;
      for (const MarkerDetection& m : markers) {
        const cv::Point2f middle = centre(m.corners);
        at_marker =
            at_marker ||
            (insideConvex(m.corners, toFrame(cv::Point2f(b.tl()))) &&
             insideConvex(m.corners, toFrame(cv::Point2f(b.br())))) ||
            cv::Rect2f(toFrame(cv::Point2f(b.tl())), toFrame(cv::Point2f(b.br()))).contains(middle);
      }
      if (at_marker) continue;
      const int margin = 4 + std::max(b.width, b.height) / 4;
      const cv::Rect wide =
          cv::Rect(b.x - margin, b.y - margin, b.width + 2 * margin, b.height + 2 * margin) & image;
      if (!wide.empty()) regions.push_back(wide);
    }
    for (bool merged = true; merged;) {
      merged = false;
      for (size_t i = 0; i < regions.size() && !merged; ++i)
        for (size_t j = i + 1; j < regions.size() && !merged; ++j)
          if ((regions[i] & regions[j]).area() > 0) {
            regions[i] |= regions[j];
            regions.erase(regions.begin() + static_cast<std::ptrdiff_t>(j));
            merged = true;
          }
    }
    double covered = 0.0;
    for (const cv::Rect& r : regions) covered += r.area();
    if (covered > 0.5 * image.area()) return {image};
    return regions;
  }

  // passes.edge_segments (search_passes.h: why) over `regions` of the searched image (empty: all
  // of it). On half the searched resolution when the search is at full: the segment detector's
  // cost goes with the pixels, and a marker large enough to read has sides long enough at half.
  // Its quads join the searched image's, refined on it.
  void addEdgeSegmentQuads(const QuadFitParams& params, const std::vector<MarkerDetection>& markers,
                           const std::vector<Quad>& looked_at,
                           const std::vector<cv::Rect>& regions) {
    const SearchPasses::EdgeSegments& pass = config.passes.edge_segments;
    const bool reduce = scale == 1;
    if (reduce) cv::resize(*searched, edges_image, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    const cv::Mat& image = reduce ? edges_image : *searched;
    EdgeQuadParams edges;
    edges.min_side = std::max(4.0f, params.min_side / (reduce ? 2.0f : 1.0f));
    edges.min_contrast = static_cast<float>(pass.min_contrast);
    edges.max_corner_gap = static_cast<float>(pass.max_corner_gap);
    edges.max_covered_gap = static_cast<float>(pass.max_covered_gap);
    edges.max_quads = pass.max_quads;
    // The markers already read, in the segment image's pixels (half the frame's: a reduced
    // pixel's centre is the middle of the two it averages). Other quads of the outline search
    // are no reason to skip a place: one may be a failed fit over the very marker sought.
    std::vector<Quad> known;
    for (const MarkerDetection& m : markers) {
      Quad q;
      for (int k = 0; k < 4; ++k) q.corners[k] = (m.corners[k] - cv::Point2f(0.5f, 0.5f)) * 0.5f;
      known.push_back(q);
    }
    // A solid dark quadrilateral is no marker of a code whose every id has light cells (BCH).
    const bool needs_light_cells = family.code && family.code->min_light_cells > 0;
    // A quad the outline search already read (in vain) at the same corners is not read again.
    auto readBefore = [&](const std::array<cv::Point2f, 4>& corners) {
      const float near = 2.0f * static_cast<float>(scale);
      return std::any_of(looked_at.begin(), looked_at.end(), [&](const Quad& q) {
        for (int k = 0; k < 4; ++k) {
          bool matched = false;
          for (int j = 0; j < 4 && !matched; ++j)
            matched = cv::norm(q.corners[j] - corners[k]) <= near;
          if (!matched) return false;
        }
        return true;
      });
    };
    auto add = [&](Quad quad) {
      if (!reduce) {
        const auto on_frame = onFrameCoarse(quad.corners);
        if (readBefore(on_frame) ||
            (needs_light_cells && hasFlatCodeArea(gray, on_frame, config.border)))
          return;
        found.searched.push_back(quad);  // refined on the frame when decoded
        return;
      }
      for (cv::Point2f& c : quad.corners) c = c * 2.0f + cv::Point2f(0.5f, 0.5f);
      auto refined = refineQuad(quad.corners, *searched, params);
      if (!refined) return;
      if (readBefore(refined->corners) ||
          (needs_light_cells && hasFlatCodeArea(gray, refined->corners, config.border)))
        return;
      refined->occluded = quad.occluded;
      found.searched.push_back(*refined);
    };
    if (regions.empty()) {
      for (const Quad& quad : edgeSegmentQuads(image, known, edges)) add(quad);
      return;
    }
    // Each region alone, in the segment image's pixels, its quads moved back; the cap on
    // candidates is the frame's, shared.
    const cv::Rect whole(0, 0, image.cols, image.rows);
    int left = pass.max_quads;
    for (const cv::Rect& r : regions) {
      if (left <= 0) break;
      const cv::Rect part =
          (reduce ? cv::Rect(r.x / 2, r.y / 2, (r.width + 1) / 2 + 1, (r.height + 1) / 2 + 1) : r) &
          whole;
      if (part.width < 8 || part.height < 8) continue;
      const cv::Point2f offset(static_cast<float>(part.x), static_cast<float>(part.y));
      std::vector<Quad> known_here = known;
      for (Quad& q : known_here)
        for (cv::Point2f& c : q.corners) c -= offset;
      edges.max_quads = left;
      const std::vector<Quad> quads = edgeSegmentQuads(image(part).clone(), known_here, edges);
      left -= static_cast<int>(quads.size());
      for (Quad quad : quads) {
        for (cv::Point2f& c : quad.corners) c += offset;
        add(quad);
      }
    }
  }

  // A reduced image's point in frame pixels: a reduced pixel's centre is the middle of the frame
  // pixels it averages.
  cv::Point2f toFrame(cv::Point2f reduced) const {
    const float s = static_cast<float>(scale), shift = 0.5f * (s - 1.0f);
    return reduced * s + cv::Point2f(shift, shift);
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
    if (quadArea(coarse.corners) < static_cast<float>(config.passes.thin_on_frame.refine_width_px) *
                                       longestSide(coarse.corners)) {
      params.min_side = 1.0f;
      if (const auto refined = refineQuad(coarse.corners, *searched, params)) start = *refined;
    }
    params.min_side = config.min_side_px;
    params.lens = config.lens.get();
    auto placed = refineQuad(onFrameCoarse(start.corners), *binarised, params);
    // Still fitted from the visible runs of a covered outline: its border may show the cover.
    if (placed) placed->occluded = coarse.occluded;
    return placed;
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

  // passes.place_on_frame (search_passes.h: why). The code was read where the marker was found.
  void placeOnFrame(Quad& quad, MarkerDetection& marker) const {
    const SearchPasses::PlaceOnFrame& pass = config.passes.place_on_frame;
    QuadFitParams params;
    params.min_side = config.min_side_px;
    params.lens = config.lens.get();
    if (looksSmeared(quad, gray, params)) return;
    const auto placed = refineQuad(quad.corners, gray, params);
    if (!placed) return;
    const float most = static_cast<float>(pass.most_move_px);
    for (int k = 0; k < 4; ++k) {
      const cv::Point2f d = placed->corners[k] - quad.corners[k];
      if (d.dot(d) > most * most) return;
    }
    quad.corners = placed->corners;
    quad.ideal_corners = placed->ideal_corners;
    for (int k = 0; k < 4; ++k) {
      marker.corners[k] = quad.corners[(k + 4 - marker.orientation) % 4];
      marker.ideal_corners[k] = quad.ideal_corners[(k + 4 - marker.orientation) % 4];
    }
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
    // Quads of the searched image, then those already on the frame (thin regions).
    std::vector<Quad>& quads = found.searched;
    const std::vector<Quad>& on_frame_quads = found.on_frame;
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
        // A flat code area is no marker of a code whose ids all have light cells (BCH), whoever
        // refines it: not worth refining.
        if (family.code && family.code->min_light_cells > 0 &&
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
      auto marker = readQuad(config, family, gray, quad, samples);
      if (!marker) marker = readOnBlurredEdges(config, family, gray, quad, samples);
      if (marker && place_on_frame) placeOnFrame(quad, *marker);
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
    place_on_frame = false;
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
      const bool smooth =
          config.smoothing == Smoothing::Always ||
          (config.smoothing == Smoothing::Auto &&
           (noise_sigma >= config.passes.smooth_above_noise || looksBlockCompressed(gray)));
      if (smooth) smoothBinomial3(gray, smoothed);
      binarised = smooth ? &smoothed : &gray;
      searched = binarised;
      place_on_frame = config.passes.place_on_frame.enabled && smooth &&
                       noise_sigma < config.passes.smooth_above_noise;
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
      searchEdges(time, result.markers);
      result.candidates = static_cast<int>(found.searched.size());
      result.threshold_attempts = attempt + 1;
      if (!automatic) break;
      // ARToolKitPlus: midrange of all candidates' code samples; the original system: the median
      // of the last seen marker's pixels. While nothing is found, a random threshold.
      const bool seen =
          mode == ThresholdMode::AutoMidrange ? !found.searched.empty() : !result.markers.empty();
      if (seen) {
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
    for (const Quad& quad : found.searched) {
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
      result.markers = whole_image->detect(gray);
      for (MarkerDetection& m : result.markers) {
        for (int k = 0; k < 4; ++k) {
          m.ideal_corners[k] =
              config.lens ? toFloat(config.lens->undistort(m.corners[k])) : m.corners[k];
        }
      }
      time.decode = microseconds(decode_start, Clock::now());
      // Each library thresholds the frame itself.
      result.threshold_mode = whole_image->threshold_mode;
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
  if (!impl.family.squares()) {
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
  return readQuad(impl.config, impl.family, gray, quad,
                  sampleMarker(gray, quad, impl.config.border));
}

const DetectorConfig& MarkerDetector::config() const {
  return impl_->config;
}

void MarkerDetector::setThreshold(const ThresholdSettings& settings) {
  DetectorConfig changed = impl_->config;
  changed.threshold = settings;
  validate(changed, impl_->family);
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
