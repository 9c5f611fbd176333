// `arbci gl-info`: opens a GL context (a hidden window, or headless EGL) and prints what it got.
#include <iostream>
#include <memory>

#include "arbci/render/gl_context.h"
#include "arbci/render/window_context.h"
#include "commands/commands.h"

namespace arbci::app {

void addGlInfoCommand(CLI::App& root, int& exit_code) {
  auto* command = root.add_subcommand(
      "gl-info", "Open an OpenGL context and print its vendor, renderer and version");
  auto headless = std::make_shared<bool>(false);
  command->add_flag("--headless", *headless,
                    "Use a headless EGL context (the default when no display exists)");
  command->callback([headless, &exit_code] {
    std::unique_ptr<render::GlContext> context;
    if (*headless || !render::displayAvailable()) {
      context = render::createHeadlessContext({64, 64});
    } else {
      render::WindowOptions options;
      options.visible = false;
      options.size = {64, 64};
      context = std::make_unique<render::WindowContext>(options);
    }
    const render::GlInfo info = context->info();
    std::cout << "context:  " << (context->isHeadless() ? "headless (EGL)" : "window (GLFW)")
              << "\nvendor:   " << info.vendor << "\nrenderer: " << info.renderer
              << "\nversion:  " << info.version << "\nglsl:     " << info.glsl_version << "\n";
    exit_code = 0;
  });
}

}  // namespace arbci::app
