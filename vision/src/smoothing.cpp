#include "smoothing.h"

#include <cstdint>
#include <cstdlib>
#include <vector>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace arbci::vision {
namespace {

inline std::uint8_t average(std::uint8_t a, std::uint8_t b) {
  return static_cast<std::uint8_t>((static_cast<unsigned>(a) + b + 1) >> 1);
}

// out[x] = avg(avg(a[x], c[x]), b[x]) ~ (a + 2b + c) / 4 for x in [begin, end).
void binomial(const std::uint8_t* a, const std::uint8_t* b, const std::uint8_t* c,
              std::uint8_t* out, int begin, int end) {
  int x = begin;
#ifdef __SSE2__
  for (; x + 16 <= end; x += 16) {
    const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + x));
    const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + x));
    const __m128i vc = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + x));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm_avg_epu8(_mm_avg_epu8(va, vc), vb));
  }
#endif
  for (; x < end; ++x) out[x] = average(average(a[x], c[x]), b[x]);
}

}  // namespace

void smoothBinomial3(const cv::Mat& src, cv::Mat& dst) {
  CV_Assert(src.type() == CV_8UC1);
  const int width = src.cols, height = src.rows;
  if (!dst.u || dst.u->refcount > 1 || dst.data == src.data) dst.release();
  dst.create(height, width, CV_8UC1);
  if (width < 3 || height < 3) {
    src.copyTo(dst);
    return;
  }
  thread_local std::vector<std::uint8_t> column;
  column.resize(static_cast<size_t>(width));
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* above = src.ptr<std::uint8_t>(y > 0 ? y - 1 : 0);
    const std::uint8_t* row = src.ptr<std::uint8_t>(y);
    const std::uint8_t* below = src.ptr<std::uint8_t>(y + 1 < height ? y + 1 : y);
    std::uint8_t* vertical = column.data();
    binomial(above, row, below, vertical, 0, width);
    std::uint8_t* out = dst.ptr<std::uint8_t>(y);
    binomial(vertical - 1, vertical, vertical + 1, out, 1, width - 1);
    out[0] = average(average(vertical[0], vertical[1]), vertical[0]);
    out[width - 1] =
        average(average(vertical[width - 2], vertical[width - 1]), vertical[width - 1]);
  }
}

bool looksBlockCompressed(const cv::Mat& gray) {
  // Steps across the grid's lines against the mean of the steps either side, over every 4th row
  // (vertical lines) and every 4th column (horizontal lines). An uncompressed frame gives
  // about 1 (0.90-1.08 on the bench's scenes, under 1.08 on photos); a JPEG of quality 50 gives
  // 1.28-1.53, and a webcam's JPEG frames 1.36-1.46.
  constexpr int kBlock = 8;
  constexpr double kBlockyRatio = 1.2;
  if (gray.cols < 2 * kBlock || gray.rows < 2 * kBlock) return false;
  long across = 0, beside = 0, count = 0;
  for (int y = 1; y < gray.rows; y += 4) {
    const std::uint8_t* p = gray.ptr<std::uint8_t>(y);
    for (int x = kBlock; x + 1 < gray.cols; x += kBlock) {
      across += std::abs(p[x] - p[x - 1]);
      beside += std::abs(p[x - 1] - p[x - 2]) + std::abs(p[x + 1] - p[x]);
      ++count;
    }
  }
  for (int y = kBlock; y + 1 < gray.rows; y += kBlock) {
    const std::uint8_t* above2 = gray.ptr<std::uint8_t>(y - 2);
    const std::uint8_t* above = gray.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* here = gray.ptr<std::uint8_t>(y);
    const std::uint8_t* below = gray.ptr<std::uint8_t>(y + 1);
    for (int x = 1; x < gray.cols; x += 4) {
      across += std::abs(here[x] - above[x]);
      beside += std::abs(above[x] - above2[x]) + std::abs(below[x] - here[x]);
      ++count;
    }
  }
  // One grey level added to both keeps a flat frame (no steps at all) at 1.
  return (2.0 * across + count) / static_cast<double>(beside + count) >= kBlockyRatio;
}

}  // namespace arbci::vision
