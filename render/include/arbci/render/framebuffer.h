// An offscreen framebuffer object (RGBA8 colour texture + depth/stencil) owned RAII-style.
#pragma once

#include "arbci/render/gl_context.h"
#include "arbci/render/rgba_image.h"

namespace arbci::render {

class Framebuffer {
 public:
  // Needs a current GL context. Throws GlError if the framebuffer is incomplete.
  explicit Framebuffer(Size size);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  void resize(Size size);
  unsigned int id() const { return fbo_; }
  unsigned int colorTexture() const { return color_; }
  Size size() const { return size_; }

 private:
  void create();
  void destroy();
  Size size_;
  unsigned int fbo_ = 0;
  unsigned int color_ = 0;
  unsigned int depth_ = 0;
};

// Binds `framebuffer` (0 = default) as the draw target, sets the viewport to `size` and clears
// colour and depth.
void clearFramebuffer(unsigned int framebuffer, Size size, const float (&rgba)[4]);

// Copies a colour texture of `source` size (e.g. another context's framebuffer, shared) into the
// current context's default framebuffer of `target` size, scaled to fit with its aspect ratio.
void blitTexture(unsigned int texture, Size source, Size target);

// Reads the colour attachment of `framebuffer` (0 = default) into a top-down RGBA image.
RgbaImage readPixels(unsigned int framebuffer, Size size);
// The same of a colour texture of `size` (another framebuffer's, an OpenXR swapchain image).
RgbaImage readTexture(unsigned int texture, Size size);
// The grey level (mean of R, G, B, 0-255) of one pixel, `x` from the left, `y` from the top.
int readGrey(unsigned int framebuffer, Size size, int x, int y);

}  // namespace arbci::render
