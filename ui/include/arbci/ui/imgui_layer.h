// Dear ImGui bound to a GlContext: with the GLFW backend for input in a window, or with the
// display size set by hand when headless (drawing into the context's framebuffer either way).
#pragma once

#include <string>

#include "arbci/render/gl_context.h"

namespace arbci::ui {

class ImGuiLayer {
 public:
  // `ini_path` keeps the panel layout between runs; empty disables saving (tests, screenshots).
  ImGuiLayer(render::GlContext& context, const std::string& ini_path);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void beginFrame(float delta_seconds);
  // Renders the frame's draw lists into the context's draw framebuffer.
  void endFrame();

 private:
  render::GlContext& context_;
  std::string ini_path_;
  bool glfw_backend_ = false;
};

}  // namespace arbci::ui
