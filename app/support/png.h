// Writes images as PNG files, optionally stamped with their print resolution, with a one-line
// error on failure.
#pragma once

#include <filesystem>

#include <opencv2/core/mat.hpp>

#include "arbci/render/rgba_image.h"

namespace arbci::app {

void writePng(const std::filesystem::path& path, const render::RgbaImage& image);
// `image`: 8-bit grey, BGR or BGRA. `dpi` > 0 records the resolution (a pHYs chunk), so the file
// prints at its intended size.
void writePng(const std::filesystem::path& path, const cv::Mat& image, int dpi = 0);

}  // namespace arbci::app
