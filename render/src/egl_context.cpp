// Headless GL: a surfaceless EGL display on Mesa, an OpenGL 3.3 core context, and an FBO as the
// draw target. No X server is touched (eglGetDisplay(EGL_DEFAULT_DISPLAY) would use X11 when
// DISPLAY is set, so the platform display is requested explicitly).
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "gl.h"

namespace arbci::render {
namespace {

std::string eglErrorName(EGLint code) {
  switch (code) {
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    default:
      return "EGL error " + std::to_string(code);
  }
}

[[noreturn]] void fail(const std::string& what) {
  throw GlError("headless OpenGL (EGL): " + what + " failed (" + eglErrorName(eglGetError()) +
                "); is Mesa's EGL installed (libegl1, libgl1-mesa-dri)?");
}

bool hasClientExtension(const char* name) {
  const char* extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  return extensions && std::strstr(extensions, name) != nullptr;
}

// One initialised EGL display shared by all headless contexts of the process; terminated when
// the last context using it is destroyed.
class EglDisplay {
 public:
  EglDisplay() {
    if (hasClientExtension("EGL_MESA_platform_surfaceless")) {
      display_ = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    }
    if (display_ == EGL_NO_DISPLAY && hasClientExtension("EGL_EXT_platform_device")) {
      display_ = firstDeviceDisplay();
    }
    if (display_ == EGL_NO_DISPLAY) {
      fail("eglGetPlatformDisplay (no surfaceless or device platform)");
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display_, &major, &minor)) fail("eglInitialize");
  }
  ~EglDisplay() { eglTerminate(display_); }
  EglDisplay(const EglDisplay&) = delete;
  EglDisplay& operator=(const EglDisplay&) = delete;
  EGLDisplay get() const { return display_; }

  static std::shared_ptr<EglDisplay> shared() {
    static std::mutex mutex;
    static std::weak_ptr<EglDisplay> cached;
    std::lock_guard lock(mutex);
    auto display = cached.lock();
    if (!display) {
      display = std::make_shared<EglDisplay>();
      cached = display;
    }
    return display;
  }

 private:
  static EGLDisplay firstDeviceDisplay() {
    auto queryDevices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    if (!queryDevices) return EGL_NO_DISPLAY;
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (!queryDevices(8, devices, &count) || count == 0) return EGL_NO_DISPLAY;
    return eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
  }
  EGLDisplay display_ = EGL_NO_DISPLAY;
};

class EglContext final : public GlContext {
 public:
  explicit EglContext(Size size) : display_(EglDisplay::shared()) {
    if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI(EGL_OPENGL_API)");
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT,
                                        EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_BIT,
                                        EGL_RED_SIZE,
                                        8,
                                        EGL_GREEN_SIZE,
                                        8,
                                        EGL_BLUE_SIZE,
                                        8,
                                        EGL_ALPHA_SIZE,
                                        8,
                                        EGL_DEPTH_SIZE,
                                        24,
                                        EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display_->get(), config_attributes, &config_, 1, &count) || count == 0) {
      fail("eglChooseConfig (no pbuffer-capable OpenGL config)");
    }
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         3,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
    context_ = eglCreateContext(display_->get(), config_, EGL_NO_CONTEXT, context_attributes);
    if (context_ == EGL_NO_CONTEXT) fail("eglCreateContext (OpenGL 3.3 core)");
    makeCurrent();
    framebuffer_ = std::make_unique<Framebuffer>(size);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_->id());
    glViewport(0, 0, size.width, size.height);
  }

  ~EglContext() override {
    makeCurrent();
    framebuffer_.reset();
    eglMakeCurrent(display_->get(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_->get(), context_);
  }

  void makeCurrent() override {
    if (!eglMakeCurrent(display_->get(), EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      fail("eglMakeCurrent (surfaceless)");
    }
  }
  unsigned int drawFramebuffer() const override { return framebuffer_->id(); }
  Size framebufferSize() const override { return framebuffer_->size(); }
  void present() override { glFinish(); }
  bool isHeadless() const override { return true; }
  NativeGl native() const override {
    NativeGl n;
    n.egl_display = display_->get();
    n.egl_config = config_;
    n.egl_context = context_;
    return n;
  }

 private:
  std::shared_ptr<EglDisplay> display_;
  EGLConfig config_ = nullptr;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::unique_ptr<Framebuffer> framebuffer_;
};

}  // namespace

std::unique_ptr<GlContext> createHeadlessContext(Size size) {
  if (size.width <= 0 || size.height <= 0) {
    throw GlError("headless OpenGL: framebuffer size must be positive, got " +
                  std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  return std::make_unique<EglContext>(size);
}

}  // namespace arbci::render
