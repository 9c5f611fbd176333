// `arbci screenshot`: renders the experimenter window headless (EGL) and writes it as a PNG: the
// shell, or one panel (or the HMD view) on the live data of a simulated session.
#include <unistd.h>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/session/record_text.h"
#include "arbci/session/session.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/panel_registry.h"
#include "arbci/ui/window_state.h"
#include "commands/commands.h"
#include "hmd/hmd_stage.h"
#include "hmd/open_session.h"
#include "support/cli_error.h"
#include "support/output_path.h"
#include "support/png.h"
#include "support/session_file.h"
#include "workstation/session_requests.h"

namespace arbci::app {
namespace {

struct ScreenshotOptions {
  bool headless = false;
  std::string out;
  std::string size = "1600x900";
  std::string panel;
  std::string session;
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

// A simulated session (a still head, so it goes fast) with the window's state and request sink
// beside it, as the workstation has them.
class ShotSession {
 public:
  ShotSession(const ScreenshotOptions& options, render::GlContext& context)
      : config_(configOf(options)),
        folder_(std::filesystem::temp_directory_path() /
                ("arbci-screenshot-" + std::to_string(::getpid()))),
        opened_(open(context)),
        requests_(*opened_.session, {}) {
    window_.hmd_texture = opened_.hmd->texture();
    window_.hmd_aspect = static_cast<float>(config_.hmd.width) / config_.hmd.height;
  }
  ~ShotSession() {
    session().request(session::AbortRequest{});
    session().step();
    session().step();
    opened_.session.reset();
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }
  session::Session& session() { return *opened_.session; }
  HmdStage& hmd() { return *opened_.hmd; }
  const std::filesystem::path& folder() const { return folder_; }
  bool step() {
    const bool going = session().step();
    window_.ingest(session().last(), config_);
    return going;
  }
  // Steps until `ready` holds on the last record. A live amplifier runs in real time: then the
  // picture is taken after 10 s at most, whatever the session has reached by then.
  void runUntil(const std::function<bool(const session::CycleRecord&)>& ready) {
    const auto live_limit = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (int i = 0; i < 60 * 600 && !ready(session().last()) && step(); ++i) {
      if (config_.eeg.live() && std::chrono::steady_clock::now() > live_limit) break;
    }
  }
  ui::PanelInput input() {
    return {session().last(), config_, session().operatorLog(), window_, requests_};
  }
  std::string status() {
    return session::statusLine(session().last(), config_, window_.cycleP50Ms());
  }

 private:
  static session::SessionConfig configOf(const ScreenshotOptions& options) {
    session::SessionConfig config = loadSessionOption(options.session);
    if (options.session.empty()) {
      config.cameras.head_motion_m = 0.0;
      config.cameras.head_motion_deg = 0.0;
      config.robot.speed_factor = 20.0;
    }
    return config;
  }
  OpenedSession open(render::GlContext& context) {
    session::SessionOptions session_options;
    session_options.folder = folder_;
    session_options.trials = 1;
    return openSession(config_, session_options, context);
  }
  session::SessionConfig config_;
  std::filesystem::path folder_;
  OpenedSession opened_;
  SessionRequests requests_;
  ui::WindowState window_;
};

// Draws the shell with `panels` for a few frames (ImGui settles its layout) and writes the PNG;
// `live`: the session steps between the frames.
void renderPanels(render::GlContext& context, render::Size size,
                  const std::vector<ui::Panel*>& panels, ShotSession& shot, bool live,
                  const std::string& out) {
  ui::ImGuiLayer imgui(context, "");
  ui::ExperimenterShell shell;
  for (ui::Panel* panel : panels) shell.addPanel(*panel);
  for (int frame = 0; frame < 3; ++frame) {
    if (live) shot.step();
    context.makeCurrent();
    imgui.beginFrame(1.0f / 60.0f);
    shell.draw(size, {16.7f, shot.status(), "screenshot"}, shot.input());
    render::clearFramebuffer(context.drawFramebuffer(), size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    context.present();
  }
  writePng(out, render::readPixels(context.drawFramebuffer(), size));
}

// One panel's picture by its shot (ui::panelShots()), or (no --panel) the experimenter window as
// `arbci run` opens it during the grid's flashing.
void renderPanel(const ScreenshotOptions& options, render::Size size) {
  auto context = render::createHeadlessContext(size);
  ShotSession shot(options, *context);
  if (options.panel.empty()) {
    shot.runUntil([](const session::CycleRecord& r) {
      return r.paradigm.phase == bci::Phase::CellFlashing && r.paradigm.sequence >= 2;
    });
    // The panels the window opens at start, in the registry's order (as `arbci run` shows them).
    std::vector<std::unique_ptr<ui::Panel>> owned;
    std::vector<ui::Panel*> shown;
    for (const auto& entry : ui::panels().entries()) {
      if (!entry.make.open_at_start) continue;
      owned.push_back(entry.make.make());
      shown.push_back(owned.back().get());
    }
    renderPanels(*context, size, shown, shot, true, options.out);
    return;
  }
  for (const auto& [name, recipe] : ui::panelShots()) {
    if (recipe->name != options.panel) continue;
    shot.runUntil(recipe->ready);
    if (recipe->hmd_framebuffer) {
      ensureWritable(options.out);
      shot.hmd().screenshot(options.out);
      return;
    }
    const std::unique_ptr<ui::Panel> panel = ui::panels().at(name).make.make();
    if (recipe->act) {
      const ui::ShotSteps steps{[&](int frames) {
                                  for (int i = 0; i < frames && shot.step(); ++i) {
                                  }
                                },
                                [&] { return shot.input(); }, shot.folder()};
      recipe->act(*panel, steps);
    }
    renderPanels(*context, size, {panel.get()}, shot, recipe->live, options.out);
    return;
  }
}

std::vector<std::string> shotNames() {
  std::vector<std::string> names;
  for (const auto& [panel, recipe] : ui::panelShots()) names.push_back(recipe->name);
  return names;
}

std::string shotList() {
  std::string out;
  for (const auto& [panel, recipe] : ui::panelShots())
    out += (out.empty() ? "" : "; ") + recipe->name + ": " + recipe->doc;
  return out;
}

}  // namespace

void addScreenshotCommand(CLI::App& root, int& exit_code) {
  auto options = std::make_shared<ScreenshotOptions>();
  auto* command = root.add_subcommand(
      "screenshot",
      "Render the experimenter window (its session, HMD, robot and threshold panels), or one\n"
      "panel, on a simulated session's live data to a PNG (headless through EGL)");
  command->add_flag("--headless", options->headless,
                    "Render without a display through EGL (the only mode screenshots use)");
  command->add_option("--out", options->out, "PNG file to write")->required();
  command->add_option("--size", options->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  command
      ->add_option("--panel", options->panel,
                   "one panel's picture (the panels' registry): " + shotList())
      ->check(CLI::IsMember(shotNames()));
  command->add_option("--session", options->session,
                      "session file (default: the embedded simulated session, with a still head)");
  command->callback([options, &exit_code] {
    ensureWritable(options->out);
    const render::Size size = parseSize(options->size);
    renderPanel(*options, size);
    exit_code = 0;
  });
}

}  // namespace arbci::app
