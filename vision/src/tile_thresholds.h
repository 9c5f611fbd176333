// Private: a threshold per 4x4-pixel tile (2x2 on a frame averaged over 2x2 pixels, so that a
// tile always covers 4x4 of the frame's pixels). Global modes fill it with one value (plus the
// vignetting offsets); the adaptive mode takes the midrange of the tile's 12 px neighbourhood
// where it has contrast above the noise, and makes flat tiles wholly dark or light against the
// nearest coarser neighbourhood (up to 192 px) that has contrast.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/threshold.h"

namespace arbci::vision {

struct TileThresholds {
  static constexpr int kTile = 4;  // at full resolution
  int tile = kTile;                // px of the image thresholded: kTile, or 2 on a halved frame
  int cols = 0;
  int rows = 0;
  // A pixel is dark when its value is below the tile's limit (threshold + 1; 0 = never dark).
  std::vector<std::uint8_t> limit;

  std::uint8_t at(int tile_x, int tile_y) const { return limit[tile_y * cols + tile_x]; }
  // The median threshold over tiles that have one (for reporting).
  int median() const;
};

// The per-pixel limits (CV_8U, the image's size): tile values interpolated bilinearly between
// tile centres, so that the threshold surface has no steps at tile borders.
void interpolateLimits(const TileThresholds& tiles, cv::Size image, cv::Mat& limits);

// The same limits one row at a time, for a labeller that compares each row as it is made: the
// frame's limit image is never written out (a frame's worth of memory traffic saved).
class LimitRows {
 public:
  // For an image of `image` with `tiles` (kept by reference until the next reset).
  void reset(const TileThresholds& tiles, cv::Size image);
  // Row y's limits, in a buffer valid until the next call.
  const std::uint8_t* row(int y);
  // Row y's limits into `out` (the image's width). Rows asked for in any order are right;
  // in order, each tile row is expanded once.
  void blend(int y, std::uint8_t* out) const;

 private:
  const std::uint8_t* expandedRow(int tile_row) const;  // tile row expanded along x

  const TileThresholds* tiles_ = nullptr;
  int width_ = 0, wide_ = 0;
  // Three expanded tile rows (a cache, refilled as rows are asked for) and their tile rows.
  mutable std::vector<std::uint8_t> expanded_;
  mutable std::array<int, 3> slot_row_{-1, -1, -1};
  std::vector<std::uint8_t> row_;
};

// `tile`: TileThresholds::kTile, or 2 on a frame averaged over 2x2 pixels.
void fillGlobalThresholds(cv::Size image, int threshold,
                          const std::optional<Vignetting>& vignetting, TileThresholds& out,
                          int tile = TileThresholds::kTile);

// Computes adaptive tile thresholds; keeps its pyramids between frames to avoid allocation.
class AdaptiveThresholder {
 public:
  // `min_contrast` in grey levels of `smoothed`; `tile`: TileThresholds::kTile, or 2 when
  // `smoothed` is a frame averaged over 2x2 pixels (the neighbourhoods keep their size in the
  // frame's pixels: with 4 px tiles there, a marker's quiet zone would be as narrow as one).
  void fill(const cv::Mat& smoothed, int min_contrast, TileThresholds& out,
            int tile = TileThresholds::kTile);
  // After fill(): the per-pixel limits of `roi` with edge tiles split at `split` sixteenths of
  // their range instead of the usual kSplit (a darker split closes borders thinned by blur).
  // `limits` becomes a view of this thresholder's buffer, valid until the next call. With
  // `upscale` 2 (tiles of 2 px on a frame averaged over 2x2 pixels), the limits are those of
  // `roi`'s pixels in the frame, `roi` scaled by 2, interpolated there between the tiles' centres.
  void roiLimits(cv::Rect roi, int split, cv::Mat& limits, int upscale = 1);

  // After fill(): the darkest and the lightest grey level of the image filled from.
  std::pair<int, int> imageRange() const;

  // Where an edge tile's threshold sits between its minimum and maximum, in sixteenths: a little
  // below the midrange, which keeps marker borders apart from their surroundings.
  static constexpr int kSplit = 7;

 private:
  struct MinMaxGrid {
    int cols = 0, rows = 0;
    std::vector<std::uint8_t> lo, hi;
    void resize(int c, int r);
  };

  static constexpr int kLevels = 5;  // tiles of 4, 8, 16, 32 and 64 px of the frame
  int contrast_ = 8;
  int tile_ = TileThresholds::kTile;
  std::array<MinMaxGrid, kLevels> raw_, dilated_;
  std::vector<std::uint8_t> column_lo_, column_hi_;
  std::array<std::vector<std::uint8_t>, kLevels> coarse_;  // per coarse cell: threshold + 1, or 0
  TileThresholds roi_tiles_;                               // roiLimits()' scratch
  std::vector<std::uint8_t> roi_pixels_;
};

// Standard deviation of the image noise (grey levels), from the median response of a Laplacian
// mask on a subsample (robust to edges), for choosing the adaptive contrast floor.
double estimateNoiseSigma(const cv::Mat& gray);

}  // namespace arbci::vision
