// An OpenCV image shown in an ImGui panel through a GL texture kept between frames.
#pragma once

#include <memory>

#include <opencv2/core/mat.hpp>

#include "arbci/render/texture.h"

namespace arbci::ui {

class ImageView {
 public:
  // Draws `image` (grey, BGR or BGRA) scaled to `width` pixels wide; nothing for an empty image.
  void draw(const cv::Mat& image, float width);
  // The same, for a texture drawn elsewhere (e.g. the HMD framebuffer).
  static void drawTexture(unsigned int texture, float width, float height, bool flip_vertically);

 private:
  std::unique_ptr<render::Texture> texture_;
};

}  // namespace arbci::ui
