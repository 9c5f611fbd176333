// Private: sub-pixel sampling of 8-bit images (OpenCV convention: pixel centres at integers).
#pragma once

#include <algorithm>
#include <cstdint>

#include <opencv2/core/mat.hpp>

namespace arbci::vision {

// Bilinear interpolation; (x, y) must lie in [0, cols - 1) x [0, rows - 1).
inline float sampleBilinearInside(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
  const std::uint8_t* r0 = image.ptr<std::uint8_t>(y0) + x0;
  const std::uint8_t* r1 = r0 + image.step[0];
  const float top = r0[0] + fx * static_cast<float>(r0[1] - r0[0]);
  const float bottom = r1[0] + fx * static_cast<float>(r1[1] - r1[0]);
  return top + fy * (bottom - top);
}

// Bilinear interpolation, clamped at the image border.
inline float sampleBilinear(const cv::Mat& image, float x, float y) {
  if (image.cols < 2 || image.rows < 2) return image.empty() ? 0.0f : image.at<std::uint8_t>(0, 0);
  x = std::clamp(x, 0.0f, static_cast<float>(image.cols - 1) - 1e-3f);
  y = std::clamp(y, 0.0f, static_cast<float>(image.rows - 1) - 1e-3f);
  return sampleBilinearInside(image, x, y);
}

// The bounding box of `points`, grown by `margin` on every side.
template <typename Points>
cv::Rect2f boundsOf(const Points& points, float margin) {
  float x0 = points[0].x, x1 = x0, y0 = points[0].y, y1 = y0;
  for (const auto& p : points) {
    x0 = std::min(x0, p.x);
    x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  return {x0 - margin, y0 - margin, x1 - x0 + 2 * margin, y1 - y0 + 2 * margin};
}

// A sampler that skips the border clamp when the whole region of interest lies inside; the
// caller guarantees every sample falls in `region`.
class BilinearSampler {
 public:
  // `region`: the area (in pixels) all later samples fall into.
  BilinearSampler(const cv::Mat& image, const cv::Rect2f& region)
      : image_(image),
        inside_(region.x >= 0.0f && region.y >= 0.0f &&
                region.x + region.width < static_cast<float>(image.cols - 1) &&
                region.y + region.height < static_cast<float>(image.rows - 1)) {}
  float operator()(float x, float y) const {
    return inside_ ? sampleBilinearInside(image_, x, y) : sampleBilinear(image_, x, y);
  }

 private:
  const cv::Mat& image_;
  bool inside_;
};

}  // namespace arbci::vision
