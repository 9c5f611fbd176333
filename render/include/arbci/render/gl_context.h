// One OpenGL 3.3 core context abstraction with two back ends: a GLFW window and a headless
// EGL context (Mesa, no X server). Drawing code takes the context's draw framebuffer and size,
// so the same code renders into a window or into a framebuffer object that can be read back.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

namespace arbci::render {

struct Size {
  int width = 0;
  int height = 0;
  bool operator==(const Size&) const = default;
};

struct GlInfo {
  std::string vendor;
  std::string renderer;
  std::string version;
  std::string glsl_version;
};

// A GL context could not be created or used; the message says why and what to check.
class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The native handles of a context, for an OpenXR runtime to bind to (null where the back end
// has none): EGL's (headless) or GLX's (a window on X11).
struct NativeGl {
  void* egl_display = nullptr;
  void* egl_config = nullptr;
  void* egl_context = nullptr;
  void* x_display = nullptr;
  void* glx_fbconfig = nullptr;
  unsigned long glx_drawable = 0;
  void* glx_context = nullptr;
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  virtual void makeCurrent() = 0;
  // The framebuffer frames are drawn into: an FBO when headless, 0 (the back buffer) in a window.
  virtual unsigned int drawFramebuffer() const = 0;
  virtual Size framebufferSize() const = 0;
  // Ends a frame: swaps buffers in a window, waits for the GPU when headless.
  virtual void present() = 0;
  virtual bool isHeadless() const = 0;
  virtual NativeGl native() const = 0;

  // Vendor, renderer and version strings of this context (it must be current).
  GlInfo info() const;
};

// A surfaceless EGL context on Mesa rendering into an offscreen framebuffer of `size`.
// Throws GlError with the failing EGL call and the reason when no display or context opens.
std::unique_ptr<GlContext> createHeadlessContext(Size size);

}  // namespace arbci::render
