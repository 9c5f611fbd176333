// A plain RGBA8 image, rows top to bottom: what a framebuffer read-back gives.
#pragma once

#include <cstdint>
#include <vector>

namespace arbci::render {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 4, row 0 is the top row

  const std::uint8_t* at(int x, int y) const {
    return &pixels[(static_cast<size_t>(y) * width + x) * 4];
  }
};

}  // namespace arbci::render
