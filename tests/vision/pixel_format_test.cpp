// Every camera pixel format converts once to the same luminance and gives the same markers.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/pixel_format.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

// Packs a BGR image into `format` with `padding` extra bytes at the end of each row.
std::vector<std::uint8_t> pack(const cv::Mat& bgr, PixelFormat format, int padding,
                               size_t& stride) {
  const int bpp = bytesPerPixel(format);
  stride = static_cast<size_t>(bgr.cols) * bpp + padding;
  std::vector<std::uint8_t> buffer(stride * bgr.rows, 0xAB);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      const std::uint8_t b = p[0], g = p[1], r = p[2];
      std::uint8_t* out = &buffer[y * stride + static_cast<size_t>(x) * bpp];
      switch (format) {
        case PixelFormat::Gray:
          out[0] = static_cast<std::uint8_t>((r + 2 * g + b) / 4);
          break;
        case PixelFormat::Rgb:
          out[0] = r;
          out[1] = g;
          out[2] = b;
          break;
        case PixelFormat::Bgr:
          out[0] = b;
          out[1] = g;
          out[2] = r;
          break;
        case PixelFormat::Rgba:
          out[0] = r;
          out[1] = g;
          out[2] = b;
          out[3] = 255;
          break;
        case PixelFormat::Bgra:
          out[0] = b;
          out[1] = g;
          out[2] = r;
          out[3] = 255;
          break;
        case PixelFormat::Abgr:
          out[0] = 255;
          out[1] = b;
          out[2] = g;
          out[3] = r;
          break;
        case PixelFormat::Rgb565: {
          const unsigned v = ((r >> 3) << 11) | ((g >> 2) << 5) | (b >> 3);
          out[0] = static_cast<std::uint8_t>(v & 0xFF);
          out[1] = static_cast<std::uint8_t>(v >> 8);
          break;
        }
      }
    }
  }
  return buffer;
}

TEST(PixelFormats, AllFormatsGiveTheSameLuminanceAndMarkers) {
  const test::SceneLayout layout = test::makeLayout({}, 77);
  const cv::Mat gray =
      test::renderScene(layout, test::MarkerFamily::ArbciBch, test::Condition::Clean).image;
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  bgr.forEach<cv::Vec3b>([](cv::Vec3b& p, const int* pos) {
    p[0] = cv::saturate_cast<std::uint8_t>(p[0] + (pos[1] % 7));
  });
  MarkerDetector reference_detector(DetectorConfig{});
  const auto reference = reference_detector.detect(bgr).markers;
  ASSERT_FALSE(reference.empty());
  for (PixelFormat format :
       {PixelFormat::Gray, PixelFormat::Rgb, PixelFormat::Bgr, PixelFormat::Rgba, PixelFormat::Bgra,
        PixelFormat::Abgr, PixelFormat::Rgb565}) {
    size_t stride = 0;
    const auto buffer = pack(bgr, format, 13, stride);
    const ImageView view{buffer.data(), bgr.cols, bgr.rows, stride, format};
    cv::Mat luminance;
    toLuminance(view, luminance);
    ASSERT_EQ(luminance.size(), bgr.size()) << toString(format);
    cv::Mat expected;
    toLuminance(bgr, expected);
    // RGB565 keeps 5-6 bits per channel: within a few grey levels; the rest exactly.
    const double tolerance = format == PixelFormat::Rgb565 ? 6.0 : 0.0;
    EXPECT_LE(cv::norm(luminance, expected, cv::NORM_INF), tolerance) << toString(format);
    MarkerDetector detector(DetectorConfig{});
    const auto markers = detector.detect(view).markers;
    ASSERT_EQ(markers.size(), reference.size()) << toString(format);
    for (size_t i = 0; i < markers.size(); ++i) {
      EXPECT_EQ(markers[i].id, reference[i].id) << toString(format);
      EXPECT_LT(cv::norm(markers[i].corners[0] - reference[i].corners[0]), 0.3) << toString(format);
    }
  }
}

TEST(PixelFormats, LuminanceIsArToolKitPlusWeighting) {
  const std::uint8_t rgb[3] = {200, 100, 40};
  cv::Mat out;
  toLuminance(ImageView{rgb, 1, 1, 3, PixelFormat::Rgb}, out);
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), (200 + 2 * 100 + 40) / 4);
}

TEST(PixelFormats, BadBuffersAreRejectedWithAReason) {
  std::vector<std::uint8_t> data(100);
  cv::Mat out;
  EXPECT_THROW(toLuminance(ImageView{data.data(), 10, 10, 20, PixelFormat::Rgb}, out),
               std::invalid_argument);
  EXPECT_THROW(toLuminance(ImageView{nullptr, 10, 10, 10, PixelFormat::Gray}, out),
               std::invalid_argument);
  EXPECT_THROW(toLuminance(ImageView{data.data(), -1, 10, 10, PixelFormat::Gray}, out),
               std::invalid_argument);
  toLuminance(ImageView{nullptr, 0, 0, 0, PixelFormat::Gray}, out);
  EXPECT_TRUE(out.empty());
  EXPECT_THROW(pixelFormatFromString("yuyv"), std::invalid_argument);
}

}  // namespace
}  // namespace arbci::vision
