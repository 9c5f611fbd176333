// Private: sub-pixel sampling of 8-bit images (OpenCV convention: pixel centres at integers).
#pragma once

#include <algorithm>
#include <cstdint>

#include <opencv2/core/mat.hpp>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

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
  // n samples at (x, y) + k (dx, dy), k = 0 .. n - 1 (an edge profile), four at a time where
  // the region lies inside the image.
  void line(float x, float y, float dx, float dy, int n, float* out) const {
    int k = 0;
#ifdef __SSE2__
    if (inside_) {
      const __m128 steps = _mm_set_ps(3.0f, 2.0f, 1.0f, 0.0f);
      for (; k + 4 <= n; k += 4) {
        const __m128 ks = _mm_add_ps(_mm_set1_ps(static_cast<float>(k)), steps);
        gather4(_mm_add_ps(_mm_set1_ps(x), _mm_mul_ps(ks, _mm_set1_ps(dx))),
                _mm_add_ps(_mm_set1_ps(y), _mm_mul_ps(ks, _mm_set1_ps(dy))), out + k);
      }
    }
#endif
    for (; k < n; ++k)
      out[k] = (*this)(x + static_cast<float>(k) * dx, y + static_cast<float>(k) * dy);
  }

  // line() for four profiles at once: profile i's samples (x[i], y[i]) + k (dx[i], dy[i]) into
  // out[i * stride + k], each as line() computes it.
  void lines4(const float* x, const float* y, const float* dx, const float* dy, int n, float* out,
              int stride) const {
#ifdef __SSE2__
    if (inside_) {
      const __m128 xs = _mm_loadu_ps(x), ys = _mm_loadu_ps(y);
      const __m128 dxs = _mm_loadu_ps(dx), dys = _mm_loadu_ps(dy);
      for (int k = 0; k < n; ++k) {
        const __m128 ks = _mm_set1_ps(static_cast<float>(k));
        alignas(16) float values[4];
        gather4(_mm_add_ps(xs, _mm_mul_ps(ks, dxs)), _mm_add_ps(ys, _mm_mul_ps(ks, dys)), values);
        for (int i = 0; i < 4; ++i) out[i * stride + k] = values[i];
      }
      return;
    }
#endif
    for (int i = 0; i < 4; ++i) line(x[i], y[i], dx[i], dy[i], n, out + i * stride);
  }

  // Four samples: out[i] = operator()(x[i], y[i]).
  void four(const float* x, const float* y, float* out) const {
#ifdef __SSE2__
    if (inside_) {
      gather4(_mm_loadu_ps(x), _mm_loadu_ps(y), out);
      return;
    }
#endif
    for (int i = 0; i < 4; ++i) out[i] = (*this)(x[i], y[i]);
  }

  // Four area samples: out[i] the sum of five samples, (x[i], y[i]) and that +- (ax[i], ay[i]) and
  // +- (bx[i], by[i]), added in that order.
  void cross4(const float* x, const float* y, const float* ax, const float* ay, const float* bx,
              const float* by, float* out) const {
#ifdef __SSE2__
    if (inside_) {
      const __m128 xs = _mm_loadu_ps(x), ys = _mm_loadu_ps(y);
      const __m128 axs = _mm_loadu_ps(ax), ays = _mm_loadu_ps(ay);
      const __m128 bxs = _mm_loadu_ps(bx), bys = _mm_loadu_ps(by);
      alignas(16) float centre[4], plus_a[4], minus_a[4], plus_b[4], minus_b[4];
      gather4(xs, ys, centre);
      gather4(_mm_add_ps(xs, axs), _mm_add_ps(ys, ays), plus_a);
      gather4(_mm_sub_ps(xs, axs), _mm_sub_ps(ys, ays), minus_a);
      gather4(_mm_add_ps(xs, bxs), _mm_add_ps(ys, bys), plus_b);
      gather4(_mm_sub_ps(xs, bxs), _mm_sub_ps(ys, bys), minus_b);
      __m128 sum = _mm_add_ps(_mm_load_ps(centre), _mm_load_ps(plus_a));
      sum = _mm_add_ps(sum, _mm_load_ps(minus_a));
      sum = _mm_add_ps(sum, _mm_load_ps(plus_b));
      _mm_storeu_ps(out, _mm_add_ps(sum, _mm_load_ps(minus_b)));
      return;
    }
#endif
    for (int i = 0; i < 4; ++i) {
      const BilinearSampler& at = *this;
      out[i] = at(x[i], y[i]) + at(x[i] + ax[i], y[i] + ay[i]) + at(x[i] - ax[i], y[i] - ay[i]) +
               at(x[i] + bx[i], y[i] + by[i]) + at(x[i] - bx[i], y[i] - by[i]);
    }
  }

 private:
#ifdef __SSE2__
  // Bilinear samples at four points inside the image, as sampleBilinearInside() computes them.
  void gather4(__m128 xs, __m128 ys, float* out) const {
    const std::uint8_t* data = image_.data;
    const size_t step = image_.step[0];
    const __m128i xi = _mm_cvttps_epi32(xs), yi = _mm_cvttps_epi32(ys);  // >= 0 inside
    const __m128 fx = _mm_sub_ps(xs, _mm_cvtepi32_ps(xi)), fy = _mm_sub_ps(ys, _mm_cvtepi32_ps(yi));
    alignas(16) int xa[4], ya[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(xa), xi);
    _mm_store_si128(reinterpret_cast<__m128i*>(ya), yi);
    alignas(16) float p00[4], p01[4], p10[4], p11[4];
    for (int j = 0; j < 4; ++j) {
      const std::uint8_t* r0 = data + static_cast<size_t>(ya[j]) * step + xa[j];
      p00[j] = r0[0];
      p01[j] = r0[1];
      p10[j] = r0[step];
      p11[j] = r0[step + 1];
    }
    const __m128 a = _mm_load_ps(p00), b = _mm_load_ps(p01), c = _mm_load_ps(p10),
                 d = _mm_load_ps(p11);
    const __m128 top = _mm_add_ps(a, _mm_mul_ps(fx, _mm_sub_ps(b, a)));
    const __m128 bottom = _mm_add_ps(c, _mm_mul_ps(fx, _mm_sub_ps(d, c)));
    _mm_storeu_ps(out, _mm_add_ps(top, _mm_mul_ps(fy, _mm_sub_ps(bottom, top))));
  }
#endif

  const cv::Mat& image_;
  bool inside_;
};

}  // namespace arbci::vision
