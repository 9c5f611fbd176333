// Private: binarisation into runs of dark pixels and 8-connected component labelling of the runs
// (union-find), with each component's area, bounding box and first (top-left) pixel. A padded
// byte mask of the dark pixels is kept for contour tracing.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "tile_thresholds.h"

namespace arbci::vision {

struct PixelRun {
  int x0 = 0, x1 = 0;  // dark pixels [x0, x1) of row y
  int y = 0;
  int parent = 0;
  int links = 0;  // runs of the row above it touches
};

struct DarkComponent {
  int area = 0;
  int min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  int first_x = 0, first_y = 0;  // the top-most, then left-most pixel
  // Light regions it encloses: by Euler's formula over its runs (as a graph whose edges are the
  // touching runs of consecutive rows, each cycle encloses one hole), links - runs + 1.
  int holes = 0;
  bool touchesBorder(int width, int height) const {
    return min_x <= 0 || min_y <= 0 || max_x >= width - 1 || max_y >= height - 1;
  }
};

class RunLabeler {
 public:
  // `limits`: per pixel, a pixel is dark when its value is below its limit (see tile_thresholds.h).
  void label(const cv::Mat& image, const cv::Mat& limits);
  // The same with the limits made row by row.
  void label(const cv::Mat& image, LimitRows& limits);

  const std::vector<DarkComponent>& components() const { return components_; }
  // 1 where the pixel is dark; (x, y) may be one pixel outside the image (never dark there).
  bool dark(int x, int y) const { return mask_[static_cast<size_t>(y + 1) * stride_ + x + 1] != 0; }
  const std::uint8_t* maskOrigin() const { return mask_.data() + stride_ + 1; }
  int maskStride() const { return stride_; }
  size_t runCount() const { return runs_.size(); }

 private:
  // `limit_of_row(y)`: row y's limits.
  template <typename LimitOfRow>
  void binarise(const cv::Mat& image, LimitOfRow limit_of_row);
  static void markDark(const std::uint8_t* pixels, const std::uint8_t* limit, int width,
                       std::uint8_t* mask, std::uint64_t* bits);
  void appendRuns(const std::uint64_t* bits, int words, int y);
  void connect();
  void collect();
  int find(int i);

  int width_ = 0, height_ = 0, stride_ = 0;
  std::vector<std::uint8_t> mask_;
  std::vector<std::uint64_t> bits_;  // the current row's dark pixels, bit x of word x / 64
  std::vector<PixelRun> runs_;
  std::vector<int> row_begin_;  // runs of row y are [row_begin_[y], row_begin_[y + 1])
  std::vector<int> component_of_root_;
  std::vector<DarkComponent> components_;
};

}  // namespace arbci::vision
