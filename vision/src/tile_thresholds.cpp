#include "tile_thresholds.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace arbci::vision {
namespace {

std::uint8_t limitOf(int threshold) {
  return static_cast<std::uint8_t>(std::clamp(threshold + 1, 0, 255));
}

}  // namespace

void AdaptiveThresholder::MinMaxGrid::resize(int c, int r) {
  cols = c;
  rows = r;
  // Every cell is written by fill() before it is read.
  lo.resize(static_cast<size_t>(c) * r);
  hi.resize(static_cast<size_t>(c) * r);
}

int TileThresholds::median() const {
  // Over every 31st tile (several hundred of them): a report, not a computation the detector
  // depends on.
  std::array<int, 256> histogram{};
  int count = 0;
  for (size_t i = 0; i < limit.size(); i += 31) {
    const std::uint8_t v = limit[i];
    if (v > 0 && v < 255) {
      ++histogram[v - 1];
      ++count;
    }
  }
  int seen = 0;
  for (int v = 0; v < 256; ++v) {
    seen += histogram[v];
    if (count > 0 && seen * 2 >= count) return v;
  }
  return 0;
}

namespace {

// Pixel k of a tile of `tile` px lies between its centre and the next tile's: k below the middle
// towards tile t - 1, above it towards tile t + 1; the farther tile's weight in eighths (the
// nearer one's is 8 minus it). 4 px tiles: 3, 1, 1, 3; 2 px tiles: 2, 2.
constexpr int farWeight(int k, int tile) {
  return std::abs(2 * k + 1 - tile) * 4 / tile;
}

#ifdef __SSE2__
// Byte-lane helpers (unsigned): SSE2 has a rounded mean and saturating subtraction, but no
// unsigned compare and no truncated mean.

// (a + b) / 2, truncated: the rounded mean less the half an odd sum rounded up.
inline __m128i truncatedMean(__m128i a, __m128i b) {
  return _mm_sub_epi8(_mm_avg_epu8(a, b), _mm_and_si128(_mm_xor_si128(a, b), _mm_set1_epi8(1)));
}

// All ones where a <= b (a - b saturates to 0).
inline __m128i atMost(__m128i a, __m128i b) {
  return _mm_cmpeq_epi8(_mm_subs_epu8(a, b), _mm_setzero_si128());
}

// All ones where a > b.
inline __m128i greaterThan(__m128i a, __m128i b) {
  return _mm_xor_si128(atMost(a, b), _mm_set1_epi8(-1));
}

// (6 a + 2 b + 4) / 8 exactly (checked for all 65,536 pairs of bytes): the rounded mean of a and
// the truncated mean of a and b.
inline __m128i threeQuartersTowards(__m128i a, __m128i b) {
  return _mm_avg_epu8(a, truncatedMean(a, b));
}
#endif

// out = (w_near * near + w_far * far + 4) / 8, with w_near + w_far = 8.
void blendRows(const std::uint8_t* __restrict near, const std::uint8_t* __restrict far, int w_near,
               int w_far, std::uint8_t* __restrict out, int n) {
  int x = 0;
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128(), four = _mm_set1_epi16(4);
  const __m128i wn = _mm_set1_epi16(static_cast<short>(w_near)),
                wf = _mm_set1_epi16(static_cast<short>(w_far));
  if (w_near == 6) {  // every row of 2 px tiles
    for (; x + 16 <= n; x += 16) {
      _mm_storeu_si128(
          reinterpret_cast<__m128i*>(out + x),
          threeQuartersTowards(_mm_loadu_si128(reinterpret_cast<const __m128i*>(near + x)),
                               _mm_loadu_si128(reinterpret_cast<const __m128i*>(far + x))));
    }
  }
  for (; x + 16 <= n; x += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(near + x));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(far + x));
    const __m128i lo =
        _mm_srli_epi16(_mm_add_epi16(_mm_add_epi16(_mm_mullo_epi16(_mm_unpacklo_epi8(a, zero), wn),
                                                   _mm_mullo_epi16(_mm_unpacklo_epi8(b, zero), wf)),
                                     four),
                       3);
    const __m128i hi =
        _mm_srli_epi16(_mm_add_epi16(_mm_add_epi16(_mm_mullo_epi16(_mm_unpackhi_epi8(a, zero), wn),
                                                   _mm_mullo_epi16(_mm_unpackhi_epi8(b, zero), wf)),
                                     four),
                       3);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm_packus_epi16(lo, hi));
  }
  // The last pixels of a row narrower than a multiple of 16 (most of a small region's) as the
  // last sixteen, writing the ones before them again with the same values.
  if (x < n && n >= 16) {
    blendRows(near + n - 16, far + n - 16, w_near, w_far, out + n - 16, 16);
    x = n;
  }
#endif
  for (; x < n; ++x)
    out[x] = static_cast<std::uint8_t>((w_near * near[x] + w_far * far[x] + 4) >> 3);
}

}  // namespace

namespace {

// Tile t of a row expanded along x: out[tile * t + k] between tile t and its neighbour (the row's
// end tiles have none outside: they weigh themselves).
template <int kTileSize>
void expandTile(const std::uint8_t* __restrict v, int cols, std::uint8_t* __restrict out, int t) {
  const int left = v[t > 0 ? t - 1 : 0], here = v[t], right = v[t + 1 < cols ? t + 1 : t];
  for (int k = 0; k < kTileSize; ++k) {
    const int far = farWeight(k, kTileSize), other = 2 * k < kTileSize ? left : right;
    out[kTileSize * t + k] = static_cast<std::uint8_t>(((8 - far) * here + far * other + 4) >> 3);
  }
}

// Each tile row expanded along x (expandTile), the tiles with both neighbours several at a time.
template <int kTileSize>
void expandRow(const std::uint8_t* __restrict v, int cols, std::uint8_t* __restrict out) {
  int t = 0;
#ifdef __SSE2__
  if constexpr (kTileSize == 2) {
    // out[2t] = (6 v[t] + 2 v[t - 1] + 4) / 8, out[2t + 1] the same towards v[t + 1]; tiles 1 to
    // cols - 2 here (their neighbours exist), the ends by expandTile.
    expandTile<2>(v, cols, out, 0);
    auto sixteenFrom = [&](int first) {  // tiles first .. first + 15
      const __m128i h = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + first));
      const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + first - 1));
      const __m128i r = _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + first + 1));
      const __m128i even = threeQuartersTowards(h, l), odd = threeQuartersTowards(h, r);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * first), _mm_unpacklo_epi8(even, odd));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * first + 16),
                       _mm_unpackhi_epi8(even, odd));
    };
    t = 1;
    for (; t + 17 <= cols; t += 16) sixteenFrom(t);
    // The tiles left but the last as the sixteen before it (writing some again, alike).
    if (t + 1 < cols && cols >= 18) {
      sixteenFrom(cols - 17);
      t = cols - 1;
    }
  }
  if constexpr (kTileSize == 4) {
    // The four weights of the far tile (3, 1, 1, 3 eighths) in 16-bit lanes, eight tiles at a
    // time: the full search expands every tile row of the frame, and one tile at a time this was a
    // tenth of its labelling. Tiles 1 to cols - 2 here, the ends by expandTile.
    const __m128i zero = _mm_setzero_si128(), four = _mm_set1_epi16(4);
    const __m128i one = _mm_set1_epi16(1), three = _mm_set1_epi16(3);
    const __m128i five = _mm_set1_epi16(5), seven = _mm_set1_epi16(7);
    auto load8 = [&](int first) {
      return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(v + first)), zero);
    };
    // (near_weight h + far_weight o + 4) / 8
    auto weighted = [&](__m128i near_weight, __m128i h, __m128i far_weight, __m128i o) {
      return _mm_srli_epi16(
          _mm_add_epi16(
              _mm_add_epi16(_mm_mullo_epi16(near_weight, h), _mm_mullo_epi16(far_weight, o)), four),
          3);
    };
    expandTile<4>(v, cols, out, 0);
    for (t = 1; t + 9 <= cols; t += 8) {
      const __m128i h = load8(t), l = load8(t - 1), r = load8(t + 1);
      const __m128i a0 = weighted(five, h, three, l), a1 = weighted(seven, h, one, l);
      const __m128i a2 = weighted(seven, h, one, r), a3 = weighted(five, h, three, r);
      // Interleaved to a0 a1 a2 a3 per tile: pairs in 32-bit lanes, then the pairs' pairs.
      const __m128i lo01 = _mm_unpacklo_epi16(a0, a1), lo23 = _mm_unpacklo_epi16(a2, a3);
      const __m128i hi01 = _mm_unpackhi_epi16(a0, a1), hi23 = _mm_unpackhi_epi16(a2, a3);
      _mm_storeu_si128(
          reinterpret_cast<__m128i*>(out + 4 * t),
          _mm_packus_epi16(_mm_unpacklo_epi32(lo01, lo23), _mm_unpackhi_epi32(lo01, lo23)));
      _mm_storeu_si128(
          reinterpret_cast<__m128i*>(out + 4 * t + 16),
          _mm_packus_epi16(_mm_unpacklo_epi32(hi01, hi23), _mm_unpackhi_epi32(hi01, hi23)));
    }
  }
#endif
  for (; t < cols; ++t) expandTile<kTileSize>(v, cols, out, t);
}

}  // namespace

void LimitRows::reset(const TileThresholds& tiles, cv::Size image) {
  tiles_ = &tiles;
  width_ = image.width;
  wide_ = tiles.cols * tiles.tile;
  // Tile rows are expanded along x when first needed, into three slots (a row blends its tile
  // row with the one above or below; rows come in order), then blended along y (own code rather
  // than cv::resize, which would hand this small job to OpenCV's thread pool).
  expanded_.resize(3 * static_cast<size_t>(wide_));
  slot_row_ = {-1, -1, -1};
  row_.resize(static_cast<size_t>(width_));
}

const std::uint8_t* LimitRows::expandedRow(int ty) const {
  const int slot = ty % 3;
  std::uint8_t* out = &expanded_[static_cast<size_t>(slot) * wide_];
  if (slot_row_[slot] != ty) {
    const std::uint8_t* v = &tiles_->limit[static_cast<size_t>(ty) * tiles_->cols];
    if (tiles_->tile == 2) {
      expandRow<2>(v, tiles_->cols, out);
    } else {
      expandRow<TileThresholds::kTile>(v, tiles_->cols, out);
    }
    slot_row_[slot] = ty;
  }
  return out;
}

void LimitRows::blend(int y, std::uint8_t* out) const {
  const int tile = tiles_->tile, rows = tiles_->rows;
  // Tiles of 2 or 4 px: shifts, not divisions (a small region's rows are only a few dozen px).
  const int shift = tile == 2 ? 1 : 2;
  const int t = y >> shift, k = y & (tile - 1), far = std::abs(2 * k + 1 - tile) << (2 - shift);
  const int other = 2 * k < tile ? std::max(0, t - 1) : std::min(rows - 1, t + 1);
  blendRows(expandedRow(t), expandedRow(other), 8 - far, far, out, width_);
}

const std::uint8_t* LimitRows::row(int y) {
  blend(y, row_.data());
  return row_.data();
}

void interpolateLimits(const TileThresholds& tiles, cv::Size image, cv::Mat& limits) {
  thread_local LimitRows rows;
  rows.reset(tiles, image);
  limits.create(image, CV_8UC1);
  for (int y = 0; y < image.height; ++y) rows.blend(y, limits.ptr<std::uint8_t>(y));
}

void fillGlobalThresholds(cv::Size image, int threshold,
                          const std::optional<Vignetting>& vignetting, TileThresholds& out,
                          int tile) {
  out.tile = tile;
  out.cols = (image.width + tile - 1) / tile;
  out.rows = (image.height + tile - 1) / tile;
  out.limit.assign(static_cast<size_t>(out.cols) * out.rows, limitOf(threshold));
  if (!vignetting) return;
  // Offset at normalised position (u, v) in [0, 1]^2 from the centre: bilinear between the
  // centre (0), the mid-edges and the corners, as ARToolKitPlus's piecewise-linear compensation.
  for (int ty = 0; ty < out.rows; ++ty) {
    const double v = std::abs((ty * tile + tile * 0.5) / (image.height * 0.5) - 1.0);
    for (int tx = 0; tx < out.cols; ++tx) {
      const double u = std::abs((tx * tile + tile * 0.5) / (image.width * 0.5) - 1.0);
      const double offset = (1 - u) * v * vignetting->top_bottom +
                            u * (1 - v) * vignetting->left_right + u * v * vignetting->corners;
      out.limit[ty * out.cols + tx] = limitOf(threshold + static_cast<int>(std::lround(offset)));
    }
  }
}

namespace {

// The loops below run over byte rows; __restrict tells the compiler the rows do not overlap, so
// that it vectorises them.
inline std::uint8_t minimum(std::uint8_t a, std::uint8_t b) {
  return a < b ? a : b;
}
inline std::uint8_t maximum(std::uint8_t a, std::uint8_t b) {
  return a > b ? a : b;
}

// out[x] = op(in[x - 1], in[x], in[x + 1]) with the ends clamped.
template <bool kMax>
void neighbourhood3(const std::uint8_t* __restrict in, std::uint8_t* __restrict out, int n) {
  auto op = [](std::uint8_t a, std::uint8_t b) { return kMax ? maximum(a, b) : minimum(a, b); };
  if (n == 1) {
    out[0] = in[0];
    return;
  }
  out[0] = op(in[0], in[1]);
  for (int x = 1; x < n - 1; ++x) out[x] = op(op(in[x - 1], in[x]), in[x + 1]);
  out[n - 1] = op(in[n - 2], in[n - 1]);
}

template <bool kMax>
void combine3(const std::uint8_t* __restrict a, const std::uint8_t* __restrict b,
              const std::uint8_t* __restrict c, std::uint8_t* __restrict out, int n) {
  for (int x = 0; x < n; ++x) {
    out[x] = kMax ? maximum(maximum(a[x], b[x]), c[x]) : minimum(minimum(a[x], b[x]), c[x]);
  }
}

// out[t] = op over in[4t .. 4t + 3].
template <bool kMax>
void reduce4(const std::uint8_t* __restrict in, std::uint8_t* __restrict out, int n) {
  for (int t = 0; t < n; ++t) {
    const std::uint8_t* p = in + 4 * t;
    out[t] = kMax ? maximum(maximum(p[0], p[1]), maximum(p[2], p[3]))
                  : minimum(minimum(p[0], p[1]), minimum(p[2], p[3]));
  }
}

// out[t] = op over in[2t .. 2t + 1].
template <bool kMax>
void reduce2(const std::uint8_t* __restrict in, std::uint8_t* __restrict out, int n) {
  int t = 0;
#ifdef __SSE2__
  // In 16-bit lanes: the low byte against the high one, the result in the low byte.
  const __m128i low_bytes = _mm_set1_epi16(0x00FF);
  auto pairs = [&](__m128i v) {
    const __m128i shifted = _mm_srli_epi16(v, 8);
    return _mm_and_si128(kMax ? _mm_max_epu8(v, shifted) : _mm_min_epu8(v, shifted), low_bytes);
  };
  for (; t + 16 <= n; t += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * t));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * t + 16));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + t), _mm_packus_epi16(pairs(a), pairs(b)));
  }
#endif
  for (; t < n; ++t) {
    const std::uint8_t* p = in + 2 * t;
    out[t] = kMax ? maximum(p[0], p[1]) : minimum(p[0], p[1]);
  }
}

template <bool kMax>
void accumulate(const std::uint8_t* __restrict row, std::uint8_t* __restrict into, int n) {
  for (int x = 0; x < n; ++x) into[x] = kMax ? maximum(into[x], row[x]) : minimum(into[x], row[x]);
}

}  // namespace

namespace {

// One row of tiles' neighbourhoods, and their parents' (a parent per two tiles).
struct TileRow {
  const std::uint8_t* lo;      // the 12 px neighbourhood's minimum
  const std::uint8_t* hi;      // and maximum
  const std::uint8_t* own_lo;  // the tile's own
  const std::uint8_t* own_hi;
  const std::uint8_t* parent;  // the parent's "dark below" level + 1, or 0
  const std::uint8_t* parent_lo;
  const std::uint8_t* parent_hi;
};

// The limit of each tile of a row (the first one even, so that tiles pair with their parents),
// its edge tiles split at `split_sixteenths` of their range; branch-free, through
// restrict-qualified copies of the row pointers (this loop runs over every tile). The scalar tail
// says it plainly. A weak edge beside a strong one (grey table against a marker's white quiet
// zone) is not one to split at: such a tile is classified whole, like a flat one.
void limitsOfRow(const TileRow& row, int contrast, int split_sixteenths, int cols,
                 std::uint8_t* __restrict limit) {
  const std::uint8_t* __restrict lo0 = row.lo;
  const std::uint8_t* __restrict hi0 = row.hi;
  const std::uint8_t* __restrict own_lo = row.own_lo;
  const std::uint8_t* __restrict own_hi = row.own_hi;
  const std::uint8_t* __restrict parent = row.parent;
  const std::uint8_t* __restrict lo1 = row.parent_lo;
  const std::uint8_t* __restrict hi1 = row.parent_hi;
  int tx = 0;
#ifdef __SSE2__
  // Sixteen tiles at a time, in bytes (only the split's product needs 16-bit lanes); each parent
  // byte serves two tiles. Saturating adds stand for the scalar code's clamps: three times a
  // range of 85 or more is never exceeded by a parent's range, and lo + split <= hi.
  const __m128i zero = _mm_setzero_si128(), ones = _mm_set1_epi8(1);
  const __m128i floor = _mm_set1_epi8(static_cast<char>(contrast - 1));
  const __m128i split_factor = _mm_set1_epi16(static_cast<short>(split_sixteenths));
  auto load16 = [](const std::uint8_t* p) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  };
  auto twice8 = [](const std::uint8_t* p) {  // p[0], p[0], p[1], p[1], ... p[7], p[7]
    const __m128i v = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
    return _mm_unpacklo_epi8(v, v);
  };
  auto sixteenFrom = [&](int tx) {  // tiles tx .. tx + 15, tx even
    const __m128i lo = load16(lo0 + tx), range = _mm_sub_epi8(load16(hi0 + tx), lo);
    const __m128i a = load16(own_lo + tx), b = load16(own_hi + tx);
    const __m128i level = twice8(parent + tx / 2);
    const __m128i above_range = _mm_sub_epi8(twice8(hi1 + tx / 2), twice8(lo1 + tx / 2));
    const __m128i weak =
        greaterThan(above_range, _mm_adds_epu8(_mm_adds_epu8(range, range), range));
    const __m128i has_parent = greaterThan(level, zero);
    const __m128i edge =
        _mm_andnot_si128(_mm_and_si128(weak, has_parent), greaterThan(range, floor));
    const __m128i split = _mm_packus_epi16(
        _mm_srli_epi16(_mm_mullo_epi16(_mm_unpacklo_epi8(range, zero), split_factor), 4),
        _mm_srli_epi16(_mm_mullo_epi16(_mm_unpackhi_epi8(range, zero), split_factor), 4));
    const __m128i edge_limit = _mm_adds_epu8(_mm_adds_epu8(lo, split), ones);
    const __m128i flat = _mm_and_si128(has_parent, greaterThan(level, truncatedMean(a, b)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(limit + tx),
                     _mm_or_si128(_mm_and_si128(edge, edge_limit), _mm_andnot_si128(edge, flat)));
  };
  for (; tx + 16 <= cols; tx += 16) sixteenFrom(tx);
  // The tiles left (a region's row is seldom a multiple of 16) as the sixteen before them, from
  // an even tile, writing some again with the same values.
  if (tx < cols && cols >= 17) {
    sixteenFrom((cols - 16) & ~1);
    tx = (cols - 16) % 2 == 0 ? cols : cols - 1;
  }
#endif
  for (; tx < cols; ++tx) {
    const int p = tx >> 1;
    const int lo = lo0[tx], range = hi0[tx] - lo, above = parent[p];
    const bool weak = 3 * range < hi1[p] - lo1[p];
    const bool edge = range >= contrast && !(weak && above > 0);
    const int edge_limit = std::min(255, lo + range * split_sixteenths / 16 + 1);
    const int flat_limit = above > 0 && (own_lo[tx] + own_hi[tx]) / 2 < above ? 255 : 0;
    limit[tx] = static_cast<std::uint8_t>(edge ? edge_limit : flat_limit);
  }
}

// One row of a coarse level's "dark below" levels + 1: the lower quarter of a cell's range where
// that has contrast, else its parent's (`parent`: the row of the next coarser level, a cell per
// two; nullptr at the coarsest level, whose cells without contrast get 0).
void darkBelowOfRow(const std::uint8_t* __restrict lo, const std::uint8_t* __restrict hi,
                    const std::uint8_t* __restrict parent, int contrast, int cols,
                    std::uint8_t* __restrict out) {
  int x = 0;
#ifdef __SSE2__
  // In bytes: the range cannot wrap (hi >= lo), and the quarter level is at most 255 wherever it
  // is used (a range of at least 1 keeps lo below 255).
  const __m128i zero = _mm_setzero_si128(), one = _mm_set1_epi8(1);
  const __m128i floor = _mm_set1_epi8(static_cast<char>(contrast - 1));
  const __m128i six_bits = _mm_set1_epi8(0x3F);
  for (; x + 16 <= cols; x += 16) {
    const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(lo + x));
    const __m128i range =
        _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(hi + x)), l);
    const __m128i quarter = _mm_and_si128(_mm_srli_epi16(range, 2), six_bits);
    const __m128i own = _mm_add_epi8(_mm_add_epi8(l, quarter), one);
    const __m128i flat = atMost(range, floor);  // range < contrast
    __m128i above = zero;
    if (parent) {
      const __m128i p = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(parent + x / 2));
      above = _mm_unpacklo_epi8(p, p);
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x),
                     _mm_or_si128(_mm_andnot_si128(flat, own), _mm_and_si128(flat, above)));
  }
#endif
  for (; x < cols; ++x) {
    const int range = hi[x] - lo[x];
    out[x] = range >= contrast ? static_cast<std::uint8_t>(lo[x] + range / 4 + 1)
                               : (parent ? parent[x / 2] : std::uint8_t{0});
  }
}

}  // namespace

void AdaptiveThresholder::fill(const cv::Mat& smoothed, int min_contrast, TileThresholds& out,
                               int tile) {
  const int width = smoothed.cols, height = smoothed.rows;
  if (tile != 2 && tile != TileThresholds::kTile)
    throw std::invalid_argument("adaptive threshold: tiles of 2 or 4 px, not " +
                                std::to_string(tile));
  tile_ = tile;
  // Level 0: minimum and maximum of each 4x4 tile.
  MinMaxGrid& base = raw_[0];
  base.resize((width + tile - 1) / tile, (height + tile - 1) / tile);
  column_lo_.resize(static_cast<size_t>(base.cols) * tile);
  column_hi_.resize(column_lo_.size());
  for (int ty = 0; ty < base.rows; ++ty) {
    std::uint8_t* lo = column_lo_.data();
    std::uint8_t* hi = column_hi_.data();
    std::fill(column_lo_.begin(), column_lo_.end(), 255);
    std::fill(column_hi_.begin(), column_hi_.end(), 0);
    for (int y = ty * tile; y < std::min(height, ty * tile + tile); ++y) {
      const std::uint8_t* row = smoothed.ptr<std::uint8_t>(y);
      accumulate<false>(row, lo, width);
      accumulate<true>(row, hi, width);
    }
    for (int x = width; x < base.cols * tile; ++x) {  // a partial last tile repeats its last column
      lo[x] = lo[width - 1];
      hi[x] = hi[width - 1];
    }
    if (tile == 2) {
      reduce2<false>(lo, &base.lo[static_cast<size_t>(ty) * base.cols], base.cols);
      reduce2<true>(hi, &base.hi[static_cast<size_t>(ty) * base.cols], base.cols);
    } else {
      reduce4<false>(lo, &base.lo[static_cast<size_t>(ty) * base.cols], base.cols);
      reduce4<true>(hi, &base.hi[static_cast<size_t>(ty) * base.cols], base.cols);
    }
  }
  // Coarser levels: 2x2 reductions.
  for (int level = 1; level < kLevels; ++level) {
    const MinMaxGrid& fine = raw_[level - 1];
    MinMaxGrid& coarse = raw_[level];
    coarse.resize((fine.cols + 1) / 2, (fine.rows + 1) / 2);
    // Two fine rows into one (an odd last column repeated), then pairs of columns.
    column_lo_.resize(static_cast<size_t>(2 * coarse.cols));
    column_hi_.resize(column_lo_.size());
    for (int y = 0; y < coarse.rows; ++y) {
      const size_t r0 = static_cast<size_t>(2 * y) * fine.cols;
      const size_t r1 = static_cast<size_t>(std::min(2 * y + 1, fine.rows - 1)) * fine.cols;
      std::copy_n(&fine.lo[r0], fine.cols, column_lo_.begin());
      std::copy_n(&fine.hi[r0], fine.cols, column_hi_.begin());
      accumulate<false>(&fine.lo[r1], column_lo_.data(), fine.cols);
      accumulate<true>(&fine.hi[r1], column_hi_.data(), fine.cols);
      if (fine.cols % 2) {
        column_lo_[fine.cols] = column_lo_[fine.cols - 1];
        column_hi_[fine.cols] = column_hi_[fine.cols - 1];
      }
      reduce2<false>(column_lo_.data(), &coarse.lo[static_cast<size_t>(y) * coarse.cols],
                     coarse.cols);
      reduce2<true>(column_hi_.data(), &coarse.hi[static_cast<size_t>(y) * coarse.cols],
                    coarse.cols);
    }
  }
  // 3x3 neighbourhoods, separably: down columns into a row, then along it (a row of scratch
  // rather than a grid's: less memory to pass through).
  for (int level = 0; level < kLevels; ++level) {
    const MinMaxGrid& grid = raw_[level];
    MinMaxGrid& dilated = dilated_[level];
    dilated.resize(grid.cols, grid.rows);
    column_lo_.resize(static_cast<size_t>(grid.cols));
    column_hi_.resize(column_lo_.size());
    const size_t c = static_cast<size_t>(grid.cols);
    for (int y = 0; y < grid.rows; ++y) {
      const size_t up = static_cast<size_t>(std::max(0, y - 1)) * c, here = y * c;
      const size_t down = static_cast<size_t>(std::min(grid.rows - 1, y + 1)) * c;
      combine3<false>(&grid.lo[up], &grid.lo[here], &grid.lo[down], column_lo_.data(), grid.cols);
      combine3<true>(&grid.hi[up], &grid.hi[here], &grid.hi[down], column_hi_.data(), grid.cols);
      neighbourhood3<false>(column_lo_.data(), &dilated.lo[here], grid.cols);
      neighbourhood3<true>(column_hi_.data(), &dilated.hi[here], grid.cols);
    }
  }
  // A tile with contrast in its own 12 px neighbourhood -- at least the noise floor and a third of
  // its 24 px neighbourhood's -- takes that neighbourhood's midrange. Any other tile is wholly
  // dark or wholly light, so flat regions never break up into noise speckle:
  // dark only when its level lies in the lowest quarter of the finest coarser neighbourhood with
  // contrast (the inside of a large black border stays black, while a grey table stays light and
  // cannot leak into a marker through a thin quiet zone). Where no neighbourhood up to 192 px
  // has contrast, the tile is light.
  const int contrast = std::clamp(min_contrast, 1, 255);
  // Top-down over the coarse levels: each cell's "dark below" level + 1 -- the lower quarter of
  // its own neighbourhood's range if that has contrast, else its parent's (0 = none up to the
  // coarsest level).
  for (int level = kLevels - 1; level >= 1; --level) {
    const MinMaxGrid& grid = dilated_[level];
    std::vector<std::uint8_t>& coarse = coarse_[level];
    coarse.resize(grid.lo.size());  // every cell is written below
    for (int y = 0; y < grid.rows; ++y) {
      const size_t row = static_cast<size_t>(y) * grid.cols;
      const std::uint8_t* parent =
          level + 1 < kLevels
              ? &coarse_[level + 1][static_cast<size_t>(y / 2) * dilated_[level + 1].cols]
              : nullptr;
      darkBelowOfRow(&grid.lo[row], &grid.hi[row], parent, contrast, grid.cols, &coarse[row]);
    }
  }
  contrast_ = contrast;
  out.tile = tile;
  out.cols = base.cols;
  out.rows = base.rows;
  out.limit.resize(static_cast<size_t>(out.cols) * out.rows);
  // Every tile's limit, row by row.
  const int parent_cols = dilated_[1].cols;
  for (int ty = 0; ty < out.rows; ++ty) {
    const size_t row = static_cast<size_t>(ty) * out.cols;
    const size_t parent_row = static_cast<size_t>(ty / 2) * parent_cols;
    limitsOfRow({&dilated_[0].lo[row], &dilated_[0].hi[row], &base.lo[row], &base.hi[row],
                 &coarse_[1][parent_row], &dilated_[1].lo[parent_row], &dilated_[1].hi[parent_row]},
                contrast, kSplit, out.cols, &out.limit[row]);
  }
}

std::pair<int, int> AdaptiveThresholder::imageRange() const {
  // The coarsest grid's cells cover the image: a few dozen to compare.
  const MinMaxGrid& coarsest = raw_[kLevels - 1];
  if (coarsest.lo.empty()) return {0, 0};
  return {*std::min_element(coarsest.lo.begin(), coarsest.lo.end()),
          *std::max_element(coarsest.hi.begin(), coarsest.hi.end())};
}

void AdaptiveThresholder::roiLimits(cv::Rect roi, int split, cv::Mat& limits, int upscale) {
  const int tile = tile_, cols = dilated_[0].cols, rows = dilated_[0].rows;
  // Tiles around the region (one more on each side for interpolation, the first one even),
  // resized exactly as the whole grid would be, then cropped; into buffers kept between calls (a
  // frame retries up to 18 regions, most of them small).
  const int tx0 = std::max(0, roi.x / tile - 1) & ~1, ty0 = std::max(0, roi.y / tile - 1);
  const int tx1 = std::min(cols - 1, (roi.x + roi.width - 1) / tile + 1);
  const int ty1 = std::min(rows - 1, (roi.y + roi.height - 1) / tile + 1);
  roi_tiles_.cols = tx1 - tx0 + 1;
  roi_tiles_.rows = ty1 - ty0 + 1;
  roi_tiles_.limit.resize(static_cast<size_t>(roi_tiles_.cols) * roi_tiles_.rows);
  const int parent_cols = dilated_[1].cols;
  for (int ty = ty0; ty <= ty1; ++ty) {
    const size_t row = static_cast<size_t>(ty) * cols + tx0;
    const size_t parent_row = static_cast<size_t>(ty / 2) * parent_cols + tx0 / 2;
    limitsOfRow({&dilated_[0].lo[row], &dilated_[0].hi[row], &raw_[0].lo[row], &raw_[0].hi[row],
                 &coarse_[1][parent_row], &dilated_[1].lo[parent_row], &dilated_[1].hi[parent_row]},
                contrast_, split, roi_tiles_.cols,
                &roi_tiles_.limit[static_cast<size_t>(ty - ty0) * roi_tiles_.cols]);
  }
  // Interpolated between the tiles' centres at `upscale` times the resolution (a tile's pixels
  // are the middle of the frame pixels they average).
  const int pixels = tile * upscale;
  roi_tiles_.tile = pixels;
  const cv::Size size(roi_tiles_.cols * pixels, roi_tiles_.rows * pixels);
  roi_pixels_.resize(static_cast<size_t>(size.area()));
  cv::Mat expanded(size, CV_8UC1, roi_pixels_.data());
  interpolateLimits(roi_tiles_, size, expanded);
  limits = expanded(cv::Rect((roi.x - tx0 * tile) * upscale, (roi.y - ty0 * tile) * upscale,
                             roi.width * upscale, roi.height * upscale));
}

double estimateNoiseSigma(const cv::Mat& gray) {
  if (gray.cols < 3 || gray.rows < 3) return 0.0;
  // The mask [1 -2 1; -2 4 -2; 1 -2 1] cancels smooth image content and has norm 6 on white
  // noise; the median of its absolute response over every 24th row and 2nd column is robust to
  // the minority of pixels on edges.
  std::array<int, 1024> histogram{};
  int count = 0;
  for (int y = 1; y + 1 < gray.rows; y += 24) {
    const std::uint8_t* a = gray.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* b = gray.ptr<std::uint8_t>(y);
    const std::uint8_t* c = gray.ptr<std::uint8_t>(y + 1);
    for (int x = 1; x + 1 < gray.cols; x += 2) {
      const int response = a[x - 1] - 2 * a[x] + a[x + 1] - 2 * (b[x - 1] - 2 * b[x] + b[x + 1]) +
                           c[x - 1] - 2 * c[x] + c[x + 1];
      ++histogram[std::min(std::abs(response), 1023)];
      ++count;
    }
  }
  int seen = 0, median = 0;
  for (; median < 1024; ++median) {
    seen += histogram[median];
    if (seen * 2 >= count) break;
  }
  return median / (0.6745 * 6.0);
}

}  // namespace arbci::vision
