#include "arbci/render/framebuffer.h"

#include <algorithm>

#include <cstring>
#include <string>

#include "gl.h"

namespace arbci::render {

Framebuffer::Framebuffer(Size size) : size_(size) {
  create();
}

Framebuffer::~Framebuffer() {
  destroy();
}

void Framebuffer::resize(Size size) {
  if (size == size_) return;
  destroy();
  size_ = size;
  create();
}

void Framebuffer::create() {
  glGenTextures(1, &color_);
  glBindTexture(GL_TEXTURE_2D, color_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, size_.width, size_.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, size_.width, size_.height);
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    destroy();
    throw GlError("offscreen framebuffer " + std::to_string(size_.width) + "x" +
                  std::to_string(size_.height) + " is incomplete (status 0x" +
                  std::to_string(status) + ")");
  }
}

void Framebuffer::destroy() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
  if (color_) glDeleteTextures(1, &color_);
  fbo_ = depth_ = color_ = 0;
}

void clearFramebuffer(unsigned int framebuffer, Size size, const float (&rgba)[4]) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, size.width, size.height);
  glClearColor(rgba[0], rgba[1], rgba[2], rgba[3]);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
}

int readGrey(unsigned int framebuffer, Size size, int x, int y) {
  std::uint8_t pixel[4] = {0, 0, 0, 0};
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(x, size.height - 1 - y, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel);
  return (pixel[0] + pixel[1] + pixel[2]) / 3;
}

RgbaImage readPixels(unsigned int framebuffer, Size size) {
  RgbaImage image{size.width, size.height, {}};
  image.pixels.resize(static_cast<size_t>(size.width) * size.height * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size.width, size.height, GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
  // GL rows run bottom-up; flip so row 0 is the top of the image.
  const size_t stride = static_cast<size_t>(size.width) * 4;
  std::vector<std::uint8_t> row(stride);
  for (int y = 0; y < size.height / 2; ++y) {
    auto* top = image.pixels.data() + y * stride;
    auto* bottom = image.pixels.data() + (size.height - 1 - y) * stride;
    std::memcpy(row.data(), top, stride);
    std::memcpy(top, bottom, stride);
    std::memcpy(bottom, row.data(), stride);
  }
  return image;
}

RgbaImage readTexture(unsigned int texture, Size size) {
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  RgbaImage image = readPixels(fbo, size);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);
  return image;
}

void blitTexture(unsigned int texture, Size source, Size target) {
  GLuint read = 0;
  glGenFramebuffers(1, &read);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, read);
  glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glViewport(0, 0, target.width, target.height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  const double scale = std::min(static_cast<double>(target.width) / source.width,
                                static_cast<double>(target.height) / source.height);
  const int w = static_cast<int>(source.width * scale), h = static_cast<int>(source.height * scale);
  const int x = (target.width - w) / 2, y = (target.height - h) / 2;
  glBlitFramebuffer(0, 0, source.width, source.height, x, y, x + w, y + h, GL_COLOR_BUFFER_BIT,
                    GL_LINEAR);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &read);
}

}  // namespace arbci::render
