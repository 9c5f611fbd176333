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
#include "arbci/session/session.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "commands/commands.h"
#include "hmd/hmd_stage.h"
#include "hmd/open_session.h"
#include "support/cli_error.h"
#include "support/output_path.h"
#include "support/png.h"
#include "support/session_file.h"
#include "workstation/session_model.h"

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

// Draws the shell with `panels` for a few frames (ImGui settles its layout) and writes the PNG.
void renderPanels(render::GlContext& context, render::Size size,
                  const std::vector<ui::Panel*>& panels, const std::string& status,
                  const std::string& out, const std::function<void()>& before_frame = {}) {
  ui::ImGuiLayer imgui(context, "");
  ui::ExperimenterShell shell;
  for (ui::Panel* panel : panels) shell.addPanel(*panel);
  for (int frame = 0; frame < 3; ++frame) {
    if (before_frame) before_frame();
    context.makeCurrent();
    imgui.beginFrame(1.0f / 60.0f);
    shell.draw(size, {16.7f, status, "screenshot"});
    render::clearFramebuffer(context.drawFramebuffer(), size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    context.present();
  }
  writePng(out, render::readPixels(context.drawFramebuffer(), size));
}

// Runs a simulated session (a still head, so it goes fast) until `ready`, then shows a panel, or
// (no --panel) the experimenter window as `arbci run` opens it during the grid's flashing.
void renderPanel(const ScreenshotOptions& options, render::Size size) {
  session::SessionConfig config = loadSessionOption(options.session);
  if (options.session.empty()) {
    config.cameras.head_motion_m = 0.0;
    config.cameras.head_motion_deg = 0.0;
    config.robot.speed_factor = 20.0;
  }
  auto context = render::createHeadlessContext(size);
  session::SessionOptions session_options;
  session_options.folder =
      std::filesystem::temp_directory_path() / ("arbci-screenshot-" + std::to_string(::getpid()));
  session_options.trials = 1;
  OpenedSession opened = openSession(config, session_options, *context);
  session::Session& session = *opened.session;
  SessionModel model(session);
  // A live amplifier runs in real time: the picture is taken after 10 s at most, whatever the
  // session has reached by then.
  const auto live_limit = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  auto runUntil = [&](const std::function<bool()>& ready) {
    for (int i = 0; i < 60 * 600 && !ready() && session.step(); ++i) {
      model.ingest();
      if (config.eeg.live() && std::chrono::steady_clock::now() > live_limit) break;
    }
  };
  auto phase = [&] { return session.last().paradigm.phase; };
  auto sequence = [&] { return session.last().paradigm.sequence; };
  const std::string& panel = options.panel;
  if (panel == "threshold") {
    runUntil([&] { return session.frame() > 30; });
    ui::ThresholdPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "calibration") {
    ui::CalibrationPanel p(model);
    p.holdBoard(true);
    for (int view = 0; view < 6; ++view) {
      const std::int64_t until = session.frame() + 4;
      runUntil([&] { return session.frame() >= until; });
      p.captureView();
    }
    p.calibrate();
    runUntil([&] { return session.frame() % 4 == 0; });
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "training") {
    runUntil([&] { return phase() == bci::Phase::ObjectFlashing; });
    ui::TrainingPanel p(model);
    p.setRecordings((session.folder() / "recording.bdf").string());
    p.train(true);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "session-model") {
    // The Training panel on the model the session trained after its calibration run (with
    // ErrPs on, the ErrP classifier's averages beside the P300 one's).
    runUntil([&] { return phase() == bci::Phase::ObjectFlashing; });
    ui::TrainingPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "robot") {
    runUntil([&] {
      const auto& status = session.last().robot.status;
      return phase() == bci::Phase::Grasping && status && status->progress > 0.3;
    });
    ui::RobotPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "session") {
    runUntil([&] { return phase() == bci::Phase::CellFlashing && sequence() >= 2; });
    ui::SessionPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out, [&] {
      session.step();
      model.ingest();
    });
  } else if (panel == "eeg") {
    // Several seconds of the calibration's flashing: traces, onsets and quality to show.
    runUntil([&] { return phase() == bci::Phase::CalibrationFlashing && session.time() > 12.0; });
    ui::EegPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out, [&] {
      session.step();
      model.ingest();
    });
  } else if (panel == "settings") {
    runUntil([&] { return session.frame() > 10; });
    ui::SettingsPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "log") {
    runUntil([&] { return phase() == bci::Phase::ObjectFlashing; });
    ui::OperatorLogPanel p(model);
    renderPanels(*context, size, {&p}, statusLine(session), options.out);
  } else if (panel == "hmd") {
    runUntil([&] { return phase() == bci::Phase::CellFlashing && sequence() >= 2; });
    // The HMD framebuffer itself, as the subject sees it.
    runUntil([&] { return session.frame() % 11 == 1; });
    ensureWritable(options.out);
    opened.hmd->screenshot(options.out);
  } else if (panel.empty()) {
    runUntil([&] { return phase() == bci::Phase::CellFlashing && sequence() >= 2; });
    // The panels the window opens at start, in the registry's order (as `arbci run` shows them).
    const ui::PanelContext panel_context{model, opened.hmd->texture(),
                                         static_cast<float>(config.hmd.width) / config.hmd.height};
    std::vector<std::unique_ptr<ui::Panel>> owned;
    std::vector<ui::Panel*> shown;
    for (const auto& entry : ui::panels().entries()) {
      if (!entry.make.open_at_start) continue;
      owned.push_back(entry.make.make(panel_context));
      shown.push_back(owned.back().get());
    }
    renderPanels(*context, size, shown, statusLine(session), options.out, [&] {
      session.step();
      model.ingest();
    });
  } else {
    throw CliError(
        "--panel must be threshold, calibration, training, session-model, robot, session, eeg, "
        "log, settings or hmd");
  }
  session.request(session::AbortRequest{});
  session.step();
  session.step();
  std::error_code ignored;
  std::filesystem::remove_all(session_options.folder, ignored);
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
      ->add_option(
          "--panel", options->panel,
          "threshold, calibration, training (trained on the session's recording), "
          "session-model (the Training panel on the model the session trained), robot, "
          "session, eeg (traces and quality), log (the operator log), settings or hmd (the HMD "
          "view)")
      ->check(CLI::IsMember({"threshold", "calibration", "training", "session-model", "robot",
                             "session", "eeg", "log", "settings", "hmd"}));
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
