#include "arbci/render/window_context.h"

#include <algorithm>

#include <GLFW/glfw3.h>
#include <X11/Xlib.h>
#define GLFW_EXPOSE_NATIVE_X11
#define GLFW_EXPOSE_NATIVE_GLX
#include <GL/glx.h>
#include <GLFW/glfw3native.h>

#include <atomic>
#include <cstdlib>
#include <string>

namespace arbci::render {
namespace {

std::string lastGlfwError() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown GLFW error";
}

// GLFW is initialised once per process while windows exist.
int g_windows = 0;

void acquireGlfw() {
  if (g_windows == 0 && !glfwInit()) {
    throw GlError("cannot open a window: " + lastGlfwError() +
                  " (no X display? use --headless, or run under xvfb-run)");
  }
  ++g_windows;
}

void releaseGlfw() {
  if (--g_windows == 0) glfwTerminate();
}

}  // namespace

bool displayAvailable() {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (display && *display) || (wayland && *wayland);
}

WindowContext::WindowContext(const WindowOptions& options) {
  acquireGlfw();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
  GLFWmonitor* monitor = nullptr;
  Size size = options.size;
  if (options.fullscreen_monitor >= 0) {
    int count = 0;
    GLFWmonitor** monitors = glfwGetMonitors(&count);
    if (options.fullscreen_monitor < count) {
      monitor = monitors[options.fullscreen_monitor];
      const GLFWvidmode* mode = glfwGetVideoMode(monitor);
      size = {mode->width, mode->height};
    }
  } else if (GLFWmonitor* primary = glfwGetPrimaryMonitor()) {
    // Never larger than the screen's work area (a laptop's 1280x720 shows the whole window).
    int x = 0, y = 0, width = 0, height = 0;
    glfwGetMonitorWorkarea(primary, &x, &y, &width, &height);
    if (width > 0 && height > 0)
      size = {std::min(size.width, width), std::min(size.height, height)};
  }
  window_ =
      glfwCreateWindow(size.width, size.height, options.title.c_str(), monitor, options.share_with);
  if (!window_) {
    const std::string reason = lastGlfwError();
    releaseGlfw();
    throw GlError("cannot create an OpenGL 3.3 core window: " + reason);
  }
  makeCurrent();
  glfwSwapInterval(options.vsync ? 1 : 0);
}

WindowContext::~WindowContext() {
  glfwDestroyWindow(window_);
  releaseGlfw();
}

void WindowContext::makeCurrent() {
  glfwMakeContextCurrent(window_);
}

Size WindowContext::framebufferSize() const {
  Size size;
  glfwGetFramebufferSize(window_, &size.width, &size.height);
  return size;
}

NativeGl WindowContext::native() const {
  NativeGl n;
  Display* display = glfwGetX11Display();
  GLXContext context = glfwGetGLXContext(window_);
  if (!display || !context) return n;  // not a GLX context (GLFW on EGL or Wayland)
  // The context's own frame buffer configuration, which an OpenXR runtime needs to share it.
  int id = 0;
  if (glXQueryContext(display, context, GLX_FBCONFIG_ID, &id) != Success) return n;
  const int wanted[] = {GLX_FBCONFIG_ID, id, None};
  int count = 0;
  GLXFBConfig* configs = glXChooseFBConfig(display, DefaultScreen(display), wanted, &count);
  if (!configs || count == 0) return n;
  n.x_display = display;
  n.glx_fbconfig = configs[0];
  XFree(configs);
  n.glx_drawable = glfwGetGLXWindow(window_);
  n.glx_context = context;
  return n;
}

void WindowContext::present() {
  glfwSwapBuffers(window_);
}

bool WindowContext::shouldClose() const {
  return glfwWindowShouldClose(window_);
}

void WindowContext::requestClose() {
  glfwSetWindowShouldClose(window_, GLFW_TRUE);
}

void WindowContext::pollEvents() {
  glfwPollEvents();
}

int WindowContext::monitorCount() {
  if (g_windows == 0) return 0;
  int count = 0;
  glfwGetMonitors(&count);
  return count;
}

namespace {

std::function<void(const std::string&)> g_save_on_loss;
int g_loss_exit_code = 1;

// Xlib calls this when the connection to the X server breaks, and ends the process when it
// returns: it never does. A second loss met while saving (a stop that touched the display) ends
// the process as it stands.
int displayLost(Display* display) {
  static std::atomic<bool> entered{false};
  if (!entered.exchange(true) && g_save_on_loss) {
    try {
      const char* name = display ? DisplayString(display) : nullptr;
      g_save_on_loss(std::string("the display (X server ") + (name ? name : "?") +
                     ") went away: the window could not go on");
    } catch (...) {
      // Nothing more can be saved.
    }
  }
  std::_Exit(g_loss_exit_code);
}

}  // namespace

void onDisplayLost(std::function<void(const std::string& reason)> save, int exit_code) {
  g_save_on_loss = std::move(save);
  g_loss_exit_code = exit_code;
  XSetIOErrorHandler(displayLost);
}

}  // namespace arbci::render
