// The windowed back end of GlContext: a GLFW window with an OpenGL 3.3 core context.
#pragma once

#include <functional>
#include <string>

#include "arbci/render/gl_context.h"

struct GLFWwindow;
struct GLFWmonitor;

namespace arbci::render {

struct WindowOptions {
  std::string title = "ARBCI";
  Size size{1600, 900};
  bool visible = true;
  // Full screen on this monitor index (0 = primary); negative for a normal window.
  int fullscreen_monitor = -1;
  // Share GL objects (textures) with this window, e.g. the HMD mirror with the main window.
  GLFWwindow* share_with = nullptr;
  bool vsync = true;
};

class WindowContext final : public GlContext {
 public:
  // Throws GlError when GLFW cannot initialise (no display) or the context cannot be created.
  explicit WindowContext(const WindowOptions& options);
  ~WindowContext() override;

  void makeCurrent() override;
  unsigned int drawFramebuffer() const override { return 0; }
  Size framebufferSize() const override;
  void present() override;
  bool isHeadless() const override { return false; }
  NativeGl native() const override;

  bool shouldClose() const;
  void requestClose();
  GLFWwindow* window() const { return window_; }
  static void pollEvents();
  // Number of monitors GLFW sees (0 when GLFW is not initialised).
  static int monitorCount();

 private:
  GLFWwindow* window_ = nullptr;
};

// True when a window system is reachable (an X display), so a window could open.
bool displayAvailable();

// What to do when the window system goes away under the windows (the X server killed, the
// session logged out): Xlib would end the process on the spot, and whatever was not yet saved
// would be lost. `save` is called once, with the reason, on the thread that met the loss; it must
// not draw. Then the process ends with `exit_code` at once (no destructor runs: the display's
// objects are gone). Call once a window exists.
void onDisplayLost(std::function<void(const std::string& reason)> save, int exit_code);

}  // namespace arbci::render
