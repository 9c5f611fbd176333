#include "workstation/start_error_window.h"

#include <chrono>
#include <iostream>
#include <optional>

#include "arbci/bci/sample_clock.h"
#include "arbci/render/framebuffer.h"
#include "arbci/render/window_context.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/start_error_screen.h"
#include "support/interrupt.h"
#include "workstation/experimenter_script.h"

namespace arbci::app {

bool showStartError(const std::string& message, const std::filesystem::path& script_file) {
  try {
    std::optional<ExperimenterScript> script;
    if (!script_file.empty()) script.emplace(script_file);
    render::WindowOptions options;
    options.title = "ARBCI workstation";
    render::WindowContext window(options);
    ui::ImGuiLayer imgui(window, "");
    watchInterrupts();
    const std::string phase = "cannot start";
    auto last = std::chrono::steady_clock::now();
    while (!window.shouldClose() && !interruptRequested()) {
      render::WindowContext::pollEvents();
      window.makeCurrent();
      const auto now = std::chrono::steady_clock::now();
      const float frame_s = std::chrono::duration<float>(now - last).count();
      last = now;
      const render::Size size = window.framebufferSize();
      ui::SyntheticInput input;
      if (script) input = script->beforeFrame(bci::hostSeconds(), phase);
      imgui.beginFrame(frame_s, script ? &input : nullptr);
      const bool quit = ui::drawStartError(static_cast<float>(size.width),
                                           static_cast<float>(size.height), message);
      render::clearFramebuffer(0, size, {0.08f, 0.09f, 0.11f, 1.0f});
      imgui.endFrame();
      if (script) {
        script->afterFrame(window, size, phase, 0.0);
        if (!script->error().empty()) {
          std::cerr << "error: " << script->error() << "\n";
          return false;
        }
      }
      window.present();
      if (quit) break;
    }
    return true;
  } catch (const std::exception& error) {
    std::cerr << "(the window could not show it: " << error.what() << ")\n";
    return false;
  }
}

}  // namespace arbci::app
