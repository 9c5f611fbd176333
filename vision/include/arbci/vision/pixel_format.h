// Camera pixel formats, converted once per frame to the 8-bit luminance the tracker works on.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core/mat.hpp>

namespace arbci::vision {

enum class PixelFormat { Gray, Rgb, Bgr, Rgba, Bgra, Abgr, Rgb565 };

std::string toString(PixelFormat format);
// "gray", "rgb", "bgr", "rgba", "bgra", "abgr", "rgb565"; throws std::invalid_argument.
PixelFormat pixelFormatFromString(const std::string& text);
int bytesPerPixel(PixelFormat format);

// A frame as a camera delivers it: not owned; `stride` is bytes per row (>= width * bpp).
struct ImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::size_t stride = 0;
  PixelFormat format = PixelFormat::Gray;
};

// Luminance as ARToolKitPlus reads colour, (R + 2G + B) / 4. Throws std::invalid_argument for
// a null buffer with a non-zero size, negative sizes or a stride smaller than a row.
void toLuminance(const ImageView& view, cv::Mat& gray);
// The same for an OpenCV image: 1 channel (gray; `gray` then shares its pixels), 3 (BGR) or
// 4 (BGRA), 8-bit. `gray` is reallocated rather than overwritten when it shares pixels.
void toLuminance(const cv::Mat& image, cv::Mat& gray);

}  // namespace arbci::vision
