#include "run_labeling.h"

#include <algorithm>
#include <cstring>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace arbci::vision {
void RunLabeler::label(const cv::Mat& image, const cv::Mat& limits) {
  CV_Assert(limits.type() == CV_8UC1 && limits.size() == image.size());
  binarise(image, [&](int y) { return limits.ptr<std::uint8_t>(y); });
  connect();
  collect();
}

void RunLabeler::label(const cv::Mat& image, LimitRows& limits) {
  binarise(image, [&](int y) { return limits.row(y); });
  connect();
  collect();
}

template <typename LimitOfRow>
void RunLabeler::binarise(const cv::Mat& image, LimitOfRow limit_of_row) {
  width_ = image.cols;
  height_ = image.rows;
  stride_ = width_ + 2;
  // Every interior byte is written below; only the one-pixel frame must be cleared.
  mask_.resize(static_cast<size_t>(stride_) * (height_ + 2));
  std::fill_n(mask_.begin(), stride_, 0);
  std::fill_n(mask_.end() - stride_, stride_, 0);
  for (int y = 1; y <= height_; ++y) {
    mask_[static_cast<size_t>(y) * stride_] = 0;
    mask_[static_cast<size_t>(y) * stride_ + stride_ - 1] = 0;
  }
  runs_.clear();
  row_begin_.assign(static_cast<size_t>(height_) + 1, 0);
  const int words = (width_ + 63) / 64;
  bits_.assign(static_cast<size_t>(words), 0);
  for (int y = 0; y < height_; ++y) {
    const std::uint8_t* pixels = image.ptr<std::uint8_t>(y);
    std::uint8_t* mask = mask_.data() + static_cast<size_t>(y + 1) * stride_ + 1;
    markDark(pixels, limit_of_row(y), width_, mask, bits_.data());
    row_begin_[y] = static_cast<int>(runs_.size());
    appendRuns(bits_.data(), words, y);
  }
  row_begin_[height_] = static_cast<int>(runs_.size());
}

void RunLabeler::markDark(const std::uint8_t* pixels, const std::uint8_t* limit, int width,
                          std::uint8_t* mask, std::uint64_t* bits) {
  const int words = (width + 63) / 64;
  std::fill_n(bits, words, 0);
  int x = 0;
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128(), one = _mm_set1_epi8(1);
  auto sixteen = [&](int at) {
    const __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pixels + at));
    const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(limit + at));
    // limit - value saturates to 0 exactly when the pixel is not dark.
    const __m128i light = _mm_cmpeq_epi8(_mm_subs_epu8(l, p), zero);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(mask + at), _mm_andnot_si128(light, one));
    const std::uint64_t dark = ~static_cast<unsigned>(_mm_movemask_epi8(light)) & 0xFFFFu;
    bits[at >> 6] |= dark << (at & 63);
    // Sixteen pixels from `at` may cross into the next word.
    if ((at & 63) > 48) bits[(at >> 6) + 1] |= dark >> (64 - (at & 63));
  };
  for (; x + 16 <= width; x += 16) sixteen(x);
  // The last pixels (a region narrower than a multiple of 16) as the last sixteen, again
  // writing the pixels before them with the same values.
  if (x < width && width >= 16) {
    sixteen(width - 16);
    x = width;
  }
#endif
  for (; x < width; ++x) {
    const bool dark = pixels[x] < limit[x];
    mask[x] = dark;
    bits[x >> 6] |= static_cast<std::uint64_t>(dark) << (x & 63);
  }
}

void RunLabeler::appendRuns(const std::uint64_t* bits, int words, int y) {
  // Bit x of `edges` is set where pixel x differs from pixel x - 1 (the one left of the row is
  // light): runs start and end at alternate edges.
  bool inside = false;
  int start = 0;
  std::uint64_t previous = 0;  // the last pixel of the word before
  for (int w = 0; w < words; ++w) {
    const std::uint64_t word = bits[w];
    std::uint64_t edges = word ^ ((word << 1) | previous);
    previous = word >> 63;
    while (edges != 0) {
      const int x = w * 64 + __builtin_ctzll(edges);
      edges &= edges - 1;
      if (inside) {
        const int index = static_cast<int>(runs_.size());
        runs_.push_back({start, x, y, index});
      } else {
        start = x;
      }
      inside = !inside;
    }
  }
  if (inside) {
    const int index = static_cast<int>(runs_.size());
    runs_.push_back({start, width_, y, index});
  }
}

int RunLabeler::find(int i) {
  while (runs_[i].parent != i) {
    runs_[i].parent = runs_[runs_[i].parent].parent;  // path halving
    i = runs_[i].parent;
  }
  return i;
}

void RunLabeler::connect() {
  for (int y = 1; y < height_; ++y) {
    int i = row_begin_[y - 1];
    const int i_end = row_begin_[y];
    int j = row_begin_[y];
    const int j_end = row_begin_[y + 1];
    while (i < i_end && j < j_end) {
      const PixelRun& above = runs_[i];
      const PixelRun& here = runs_[j];
      // 8-connected when the runs overlap or touch diagonally.
      if (above.x0 <= here.x1 && here.x0 <= above.x1) {
        const int a = find(i);
        // The smaller index becomes the root, so a root is its component's first run (and every
        // run's parent comes before it). A run's first link finds it still its own root.
        if (runs_[j].links++ == 0) {
          runs_[j].parent = a;
        } else {
          const int b = find(j);
          if (a < b) {
            runs_[b].parent = a;
          } else if (b < a) {
            runs_[a].parent = b;
          }
        }
      }
      if (above.x1 < here.x1) {
        ++i;
      } else {
        ++j;
      }
    }
  }
}

void RunLabeler::collect() {
  components_.clear();
  component_of_root_.assign(runs_.size(), -1);
  for (int i = 0; i < static_cast<int>(runs_.size()); ++i) {
    // Parents come before their runs: in this order a run's parent already points at its root.
    PixelRun& run = runs_[i];
    run.parent = runs_[run.parent].parent;
    const int root = run.parent;
    if (root == i) {
      component_of_root_[i] = static_cast<int>(components_.size());
      components_.push_back({0, run.x0, run.x1 - 1, run.y, run.y, run.x0, run.y, 1});
    }
    DarkComponent& component = components_[component_of_root_[root]];
    component.area += run.x1 - run.x0;
    component.holes += run.links - 1;
    component.min_x = std::min(component.min_x, run.x0);
    component.max_x = std::max(component.max_x, run.x1 - 1);
    component.max_y = run.y;  // rows arrive in order
  }
}

}  // namespace arbci::vision
