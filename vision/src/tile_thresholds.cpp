#include "tile_thresholds.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

namespace arbci::vision {
namespace {

std::uint8_t limitOf(int threshold) { return static_cast<std::uint8_t>(std::clamp(threshold + 1, 0, 255)); }

}  // namespace

void AdaptiveThresholder::MinMaxGrid::resize(int c, int r) {
  cols = c;
  rows = r;
  lo.assign(static_cast<size_t>(c) * r, 255);
  hi.assign(static_cast<size_t>(c) * r, 0);
}

int TileThresholds::median() const {
  // Over every 7th tile: a report, not a computation the detector depends on.
  std::array<int, 256> histogram{};
  int count = 0;
  for (size_t i = 0; i < limit.size(); i += 7) {
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

void interpolateLimits(const TileThresholds& tiles, cv::Size image, cv::Mat& limits) {
  const cv::Mat grid(tiles.rows, tiles.cols, CV_8UC1, const_cast<std::uint8_t*>(tiles.limit.data()));
  // Tile t's centre is pixel 4t + 1.5, which is where INTER_LINEAR puts source sample t when
  // scaling by 4; a partial last tile shifts this by under half a pixel.
  cv::resize(grid, limits, image, 0, 0, cv::INTER_LINEAR);
}

void fillGlobalThresholds(cv::Size image, int threshold, const std::optional<Vignetting>& vignetting,
                          TileThresholds& out) {
  const int tile = TileThresholds::kTile;
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
inline std::uint8_t minimum(std::uint8_t a, std::uint8_t b) { return a < b ? a : b; }
inline std::uint8_t maximum(std::uint8_t a, std::uint8_t b) { return a > b ? a : b; }

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

template <bool kMax>
void accumulate(const std::uint8_t* __restrict row, std::uint8_t* __restrict into, int n) {
  for (int x = 0; x < n; ++x) into[x] = kMax ? maximum(into[x], row[x]) : minimum(into[x], row[x]);
}

}  // namespace

void AdaptiveThresholder::fill(const cv::Mat& smoothed, int min_contrast, TileThresholds& out) {
  const int width = smoothed.cols, height = smoothed.rows, tile = TileThresholds::kTile;
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
    reduce4<false>(lo, &base.lo[static_cast<size_t>(ty) * base.cols], base.cols);
    reduce4<true>(hi, &base.hi[static_cast<size_t>(ty) * base.cols], base.cols);
  }
  // Coarser levels: 2x2 reductions.
  for (int level = 1; level < kLevels; ++level) {
    const MinMaxGrid& fine = raw_[level - 1];
    MinMaxGrid& coarse = raw_[level];
    coarse.resize((fine.cols + 1) / 2, (fine.rows + 1) / 2);
    for (int y = 0; y < coarse.rows; ++y) {
      const size_t r0 = static_cast<size_t>(2 * y) * fine.cols;
      const size_t r1 = static_cast<size_t>(std::min(2 * y + 1, fine.rows - 1)) * fine.cols;
      std::uint8_t* clo = &coarse.lo[static_cast<size_t>(y) * coarse.cols];
      std::uint8_t* chi = &coarse.hi[static_cast<size_t>(y) * coarse.cols];
      for (int x = 0; x < coarse.cols; ++x) {
        const int x0 = 2 * x, x1 = std::min(2 * x + 1, fine.cols - 1);
        clo[x] = minimum(minimum(fine.lo[r0 + x0], fine.lo[r0 + x1]), minimum(fine.lo[r1 + x0], fine.lo[r1 + x1]));
        chi[x] = maximum(maximum(fine.hi[r0 + x0], fine.hi[r0 + x1]), maximum(fine.hi[r1 + x0], fine.hi[r1 + x1]));
      }
    }
  }
  // 3x3 neighbourhoods, separably: along rows into scratch, then down columns.
  for (int level = 0; level < kLevels; ++level) {
    const MinMaxGrid& grid = raw_[level];
    MinMaxGrid& dilated = dilated_[level];
    scratch_.resize(grid.cols, grid.rows);
    dilated.resize(grid.cols, grid.rows);
    const size_t c = static_cast<size_t>(grid.cols);
    for (int y = 0; y < grid.rows; ++y) {
      neighbourhood3<false>(&grid.lo[y * c], &scratch_.lo[y * c], grid.cols);
      neighbourhood3<true>(&grid.hi[y * c], &scratch_.hi[y * c], grid.cols);
    }
    for (int y = 0; y < grid.rows; ++y) {
      const size_t up = static_cast<size_t>(std::max(0, y - 1)) * c, here = y * c;
      const size_t down = static_cast<size_t>(std::min(grid.rows - 1, y + 1)) * c;
      combine3<false>(&scratch_.lo[up], &scratch_.lo[here], &scratch_.lo[down], &dilated.lo[here], grid.cols);
      combine3<true>(&scratch_.hi[up], &scratch_.hi[here], &scratch_.hi[down], &dilated.hi[here], grid.cols);
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
    coarse.assign(grid.lo.size(), 0);
    for (int y = 0; y < grid.rows; ++y) {
      for (int x = 0; x < grid.cols; ++x) {
        const size_t i = static_cast<size_t>(y) * grid.cols + x;
        const int lo = grid.lo[i], hi = grid.hi[i];
        if (hi - lo >= contrast) {
          coarse[i] = static_cast<std::uint8_t>(lo + (hi - lo) / 4 + 1);
        } else if (level + 1 < kLevels) {
          coarse[i] = coarse_[level + 1][static_cast<size_t>(y / 2) * dilated_[level + 1].cols + x / 2];
        }
      }
    }
  }
  out.cols = base.cols;
  out.rows = base.rows;
  out.limit.assign(static_cast<size_t>(out.cols) * out.rows, 0);
  const int parent_cols = dilated_[1].cols;
  for (int ty = 0; ty < out.rows; ++ty) {
    const std::uint8_t* coarse = &coarse_[1][static_cast<size_t>(ty / 2) * parent_cols];
    const std::uint8_t* lo1 = &dilated_[1].lo[static_cast<size_t>(ty / 2) * parent_cols];
    const std::uint8_t* hi1 = &dilated_[1].hi[static_cast<size_t>(ty / 2) * parent_cols];
    const std::uint8_t* lo0 = &dilated_[0].lo[static_cast<size_t>(ty) * out.cols];
    const std::uint8_t* hi0 = &dilated_[0].hi[static_cast<size_t>(ty) * out.cols];
    const std::uint8_t* own_lo = &base.lo[static_cast<size_t>(ty) * out.cols];
    const std::uint8_t* own_hi = &base.hi[static_cast<size_t>(ty) * out.cols];
    std::uint8_t* limit = &out.limit[static_cast<size_t>(ty) * out.cols];
    for (int tx = 0; tx < out.cols; ++tx) {
      const int lo = lo0[tx], hi = hi0[tx];
      const int parent = coarse[tx / 2];
      // A weak edge beside a strong one (grey table against a marker's white quiet zone) is not
      // one to split at: such a tile is classified whole, like a flat one.
      const bool weak = 3 * (hi - lo) < hi1[tx / 2] - lo1[tx / 2];
      if (hi - lo >= contrast && !(weak && parent > 0)) {
        limit[tx] = limitOf(lo + (hi - lo) * 7 / 16);
      } else if (parent > 0) {
        const int own_level = (own_lo[tx] + own_hi[tx]) / 2;
        limit[tx] = own_level < parent ? 255 : 0;  // all dark : all light
      }
    }
  }
}

double estimateNoiseSigma(const cv::Mat& gray) {
  if (gray.cols < 3 || gray.rows < 3) return 0.0;
  // The mask [1 -2 1; -2 4 -2; 1 -2 1] cancels smooth image content and has norm 6 on white
  // noise; the median of its absolute response over every 16th row and 2nd column is robust to
  // the minority of pixels on edges.
  std::array<int, 1024> histogram{};
  int count = 0;
  for (int y = 1; y + 1 < gray.rows; y += 16) {
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
