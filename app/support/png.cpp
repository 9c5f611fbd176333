#include "support/png.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "support/cli_error.h"

namespace arbci::app {
namespace {

void putBigEndian(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<std::uint8_t>(value >> shift));
}

// A pHYs chunk (pixels per metre, both axes) inserted right after the IHDR chunk.
std::vector<std::uint8_t> withResolution(const std::vector<std::uint8_t>& png, int dpi) {
  constexpr size_t kSignature = 8, kIhdrChunk = 8 + 13 + 4;
  std::vector<std::uint8_t> chunk;
  putBigEndian(chunk, 9);
  for (char c : {'p', 'H', 'Y', 's'}) chunk.push_back(static_cast<std::uint8_t>(c));
  const auto per_metre = static_cast<std::uint32_t>(std::lround(dpi / 0.0254));
  putBigEndian(chunk, per_metre);
  putBigEndian(chunk, per_metre);
  chunk.push_back(1);  // unit: metre
  const uLong crc = crc32(0L, chunk.data() + 4, static_cast<uInt>(chunk.size() - 4));
  putBigEndian(chunk, static_cast<std::uint32_t>(crc));
  std::vector<std::uint8_t> out(png.begin(), png.begin() + kSignature + kIhdrChunk);
  out.insert(out.end(), chunk.begin(), chunk.end());
  out.insert(out.end(), png.begin() + kSignature + kIhdrChunk, png.end());
  return out;
}

}  // namespace

void writePng(const std::filesystem::path& path, const render::RgbaImage& image) {
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgra;
  cv::cvtColor(rgba, bgra, cv::COLOR_RGBA2BGRA);
  writePng(path, bgra);
}

void writePng(const std::filesystem::path& path, const cv::Mat& image, int dpi) {
  std::vector<std::uint8_t> encoded;
  try {
    if (!cv::imencode(".png", image, encoded))
      throw CliError("cannot encode " + path.string() + " as PNG");
  } catch (const cv::Exception& error) {
    throw CliError("cannot encode " + path.string() + " as PNG: " + error.err);
  }
  if (dpi > 0) encoded = withResolution(encoded, dpi);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(encoded.data()),
            static_cast<std::streamsize>(encoded.size()));
  out.close();
  if (!out) throw CliError("cannot write " + path.string() + ": " + std::strerror(errno));
}

}  // namespace arbci::app
