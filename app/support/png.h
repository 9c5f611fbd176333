// Writes images as PNG files with a one-line error on failure.
#pragma once

#include <filesystem>

#include "arbci/render/rgba_image.h"

namespace arbci::app {

void writePng(const std::filesystem::path& path, const render::RgbaImage& image);

}  // namespace arbci::app
