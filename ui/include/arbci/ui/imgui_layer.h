// Dear ImGui bound to a GlContext: with the GLFW backend for input in a window, or with the
// display size set by hand when headless (drawing into the context's framebuffer either way).
#pragma once

#include <string>

#include "arbci/render/gl_context.h"

namespace arbci::ui {

// Input for one frame that replaces the mouse and keyboard (a scripted experimenter): the pointer
// at (x, y) in window pixels, the left button held or not, a key (GLFW's code, e.g. 'Q' or 257
// for Enter) pressed with or without Ctrl, and text typed.
struct SyntheticInput {
  float x = -1.0f, y = -1.0f;
  bool left_down = false;
  int key = 0;
  bool ctrl = false;
  std::string text;
};

class ImGuiLayer {
 public:
  // `ini_path` keeps the panel layout between runs; empty disables saving (tests, screenshots).
  ImGuiLayer(render::GlContext& context, const std::string& ini_path);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void beginFrame(float delta_seconds, const SyntheticInput* input = nullptr);
  // Renders the frame's draw lists into the context's draw framebuffer.
  void endFrame();

 private:
  render::GlContext& context_;
  std::string ini_path_;
  bool glfw_backend_ = false;
  int synthetic_key_ = 0;  // a key the last frame's synthetic input held
};

}  // namespace arbci::ui
