#include "support/png.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "support/cli_error.h"

namespace arbci::app {

void writePng(const std::filesystem::path& path, const render::RgbaImage& image) {
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgra;
  cv::cvtColor(rgba, bgra, cv::COLOR_RGBA2BGRA);
  bool written = false;
  try {
    written = cv::imwrite(path.string(), bgra);
  } catch (const cv::Exception& error) {
    throw CliError("cannot write " + path.string() + ": " + error.err);
  }
  if (!written) throw CliError("cannot write " + path.string());
}

}  // namespace arbci::app
