// `arbci screenshot`: renders the experimenter window headless (EGL) and writes it as a PNG.
#include <memory>
#include <string>

#include <opencv2/core/version.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/system_panel.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/output_path.h"
#include "support/png.h"

namespace arbci::app {
namespace {

struct ScreenshotOptions {
  bool headless = false;
  std::string out;
  std::string size = "1600x900";
};

render::Size parseSize(const std::string& text) {
  int width = 0, height = 0;
  char separator = 0;
  if (std::sscanf(text.c_str(), "%d%c%d", &width, &separator, &height) != 3 || separator != 'x' ||
      width < 64 || height < 64 || width > 8192 || height > 8192) {
    throw CliError("--size must be WIDTHxHEIGHT between 64 and 8192, got '" + text + "'");
  }
  return {width, height};
}

void renderShell(const ScreenshotOptions& options) {
  const render::Size size = parseSize(options.size);
  ensureWritable(options.out);
  auto context = render::createHeadlessContext(size);
  const render::GlInfo gl = context->info();
  ui::SystemPanel system({{"version", std::string("arbci ") + ARBCI_VERSION},
                          {"GL context", "headless (EGL)"},
                          {"GL vendor", gl.vendor},
                          {"GL renderer", gl.renderer},
                          {"GL version", gl.version},
                          {"OpenCV", CV_VERSION}});
  ui::ImGuiLayer imgui(*context, "");
  ui::ExperimenterShell shell;
  shell.addPanel(system);
  // ImGui lays windows out over the first frames; the third frame is settled.
  for (int frame = 0; frame < 3; ++frame) {
    imgui.beginFrame(1.0f / 60.0f);
    shell.draw(size, {16.7f, "no session", "screenshot"});
    render::clearFramebuffer(context->drawFramebuffer(), size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    context->present();
  }
  writePng(options.out, render::readPixels(context->drawFramebuffer(), size));
}

}  // namespace

void addScreenshotCommand(CLI::App& root, int& exit_code) {
  auto options = std::make_shared<ScreenshotOptions>();
  auto* command = root.add_subcommand(
      "screenshot", "Render the experimenter window to a PNG file (headless through EGL)");
  command->add_flag("--headless", options->headless,
                    "Render without a display through EGL (the only mode screenshots use)");
  command->add_option("--out", options->out, "PNG file to write")->required();
  command->add_option("--size", options->size, "Image size WIDTHxHEIGHT")
      ->capture_default_str();
  command->callback([options, &exit_code] {
    renderShell(*options);
    exit_code = 0;
  });
}

}  // namespace arbci::app
