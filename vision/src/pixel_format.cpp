#include "arbci/vision/pixel_format.h"

#include <stdexcept>

namespace arbci::vision {
namespace {

struct Channels {
  int r, g, b;  // byte offsets within a pixel
};

Channels channelsOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::Rgb:
      return {0, 1, 2};
    case PixelFormat::Bgr:
      return {2, 1, 0};
    case PixelFormat::Rgba:
      return {0, 1, 2};
    case PixelFormat::Bgra:
      return {2, 1, 0};
    case PixelFormat::Abgr:
      return {3, 2, 1};
    default:
      return {0, 0, 0};
  }
}

inline std::uint8_t luma(int r, int g, int b) {
  return static_cast<std::uint8_t>((r + 2 * g + b) >> 2);
}

}  // namespace

std::string toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::Gray:
      return "gray";
    case PixelFormat::Rgb:
      return "rgb";
    case PixelFormat::Bgr:
      return "bgr";
    case PixelFormat::Rgba:
      return "rgba";
    case PixelFormat::Bgra:
      return "bgra";
    case PixelFormat::Abgr:
      return "abgr";
    case PixelFormat::Rgb565:
      return "rgb565";
  }
  return "unknown";
}

PixelFormat pixelFormatFromString(const std::string& text) {
  for (PixelFormat f : {PixelFormat::Gray, PixelFormat::Rgb, PixelFormat::Bgr, PixelFormat::Rgba,
                        PixelFormat::Bgra, PixelFormat::Abgr, PixelFormat::Rgb565}) {
    if (toString(f) == text) return f;
  }
  throw std::invalid_argument("unknown pixel format '" + text +
                              "' (gray, rgb, bgr, rgba, bgra, abgr, rgb565)");
}

int bytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::Gray:
      return 1;
    case PixelFormat::Rgb565:
      return 2;
    case PixelFormat::Rgb:
    case PixelFormat::Bgr:
      return 3;
    default:
      return 4;
  }
}

void toLuminance(const ImageView& view, cv::Mat& gray) {
  if (view.width < 0 || view.height < 0) throw std::invalid_argument("image size is negative");
  if (view.width == 0 || view.height == 0) {
    gray.release();
    return;
  }
  if (!view.data) throw std::invalid_argument("image buffer is null");
  const int bpp = bytesPerPixel(view.format);
  if (view.stride < static_cast<std::size_t>(view.width) * bpp) {
    throw std::invalid_argument("image stride " + std::to_string(view.stride) +
                                " is smaller than a row of " + std::to_string(view.width * bpp) +
                                " bytes");
  }
  // Never write into pixels shared with another image (create() would reuse them).
  if (!gray.u || gray.u->refcount > 1) gray.release();
  gray.create(view.height, view.width, CV_8UC1);
  const Channels ch = channelsOf(view.format);
  for (int y = 0; y < view.height; ++y) {
    const std::uint8_t* in = view.data + view.stride * static_cast<std::size_t>(y);
    std::uint8_t* out = gray.ptr<std::uint8_t>(y);
    switch (view.format) {
      case PixelFormat::Gray:
        std::copy(in, in + view.width, out);
        break;
      case PixelFormat::Rgb565:
        for (int x = 0; x < view.width; ++x) {
          const unsigned v = in[2 * x] | (in[2 * x + 1] << 8);  // little-endian 5-6-5
          const int r = ((v >> 11) & 0x1F) * 255 / 31, g = ((v >> 5) & 0x3F) * 255 / 63;
          const int b = (v & 0x1F) * 255 / 31;
          out[x] = luma(r, g, b);
        }
        break;
      default:
        for (int x = 0; x < view.width; ++x) {
          const std::uint8_t* p = in + x * bpp;
          out[x] = luma(p[ch.r], p[ch.g], p[ch.b]);
        }
    }
  }
}

void toLuminance(const cv::Mat& image, cv::Mat& gray) {
  if (image.empty()) {
    gray.release();
    return;
  }
  if (image.depth() != CV_8U) throw std::invalid_argument("image must have 8-bit channels");
  PixelFormat format;
  switch (image.channels()) {
    case 1:
      format = PixelFormat::Gray;
      break;
    case 3:
      format = PixelFormat::Bgr;
      break;
    case 4:
      format = PixelFormat::Bgra;
      break;
    default:
      throw std::invalid_argument("image must have 1, 3 or 4 channels");
  }
  if (format == PixelFormat::Gray) {
    gray = image;  // shares the pixels: no conversion needed
    return;
  }
  toLuminance(ImageView{image.data, image.cols, image.rows, image.step, format}, gray);
}

}  // namespace arbci::vision
