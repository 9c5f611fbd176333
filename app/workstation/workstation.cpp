#include "workstation/workstation.h"

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include <imgui.h>

#include "arbci/core/whole_file.h"
#include "arbci/render/framebuffer.h"
#include "arbci/render/window_context.h"
#include "arbci/session/record_text.h"
#include "arbci/ui/experimenter_shell.h"
#include "arbci/ui/imgui_layer.h"
#include "arbci/ui/panel_registry.h"
#include "hmd/hmd_stage.h"
#include "hmd/open_session.h"
#include "hmd/openxr_output.h"
#include "support/interrupt.h"
#include "workstation/experimenter_script.h"
#include "workstation/session_requests.h"

namespace arbci::app {
namespace {

// Opening can take seconds (an LSL stream looked for until its timeout, an amplifier connected):
// the window and the terminal say what it waits for instead of a black window.
void showOpening(render::WindowContext& window, ui::ImGuiLayer& imgui,
                 const session::SessionConfig& config) {
  const std::string text =
      config.eeg.source == "lsl"
          ? "Opening the session: looking for the EEG stream on the Lab Streaming Layer "
            "(eeg.lsl; it waits up to its resolve timeout, then says what it found)"
          : "Opening the session: starting the EEG source (" + config.eeg.source +
                "), the cameras and the robot";
  std::cerr << text << "\n";
  render::WindowContext::pollEvents();
  window.makeCurrent();
  const render::Size size = window.framebufferSize();
  imgui.beginFrame(1.0f / 60.0f);
  ImGui::SetNextWindowPos(ImVec2(20.0f, 40.0f));
  ImGui::Begin("Opening", nullptr,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoSavedSettings);
  ImGui::TextUnformatted(text.c_str());
  ImGui::End();
  render::clearFramebuffer(0, size, {0.08f, 0.09f, 0.11f, 1.0f});
  imgui.endFrame();
  window.present();
}

// The start screen's settings applied to the run about to start: the session (not started) is
// closed and opened again in its folder with them, keeping the run's labels; the command line's
// --trials and --seed give way to the settings' own. Settings that cannot open a session (a
// device gone since they were checked) leave the session as it was, saying why.
void reopen(OpenedSession& opened, const nlohmann::json& settings, session::SessionOptions options,
            render::GlContext& context) {
  const session::SessionConfig before = opened.session->config();
  options.labels = opened.session->labels();
  options.folder = opened.session->folder();
  options.trials.reset();
  options.seed.reset();
  // Kept in the folder: the run's settings are in a file, as a session file's are.
  const std::filesystem::path file = options.folder / "settings.json";
  std::optional<session::SessionConfig> next;
  try {
    next = session::SessionConfig::parse(settings, file.string());
    session::checkNamedResources(*next);
    if (const std::string why = core::writeWholeFile(file, settings.dump(2) + "\n"); !why.empty())
      throw std::runtime_error(why);
  } catch (const std::exception& error) {
    std::cerr << "\nsettings not applied: " << error.what() << "\n";
    return;
  }
  // One session in the folder at a time: the first closes (it never started) before the next
  // writes its log, recording and session.json there; its closing summary is not this run's.
  opened = OpenedSession{};
  std::error_code ignored;
  std::filesystem::remove(options.folder / "summary.json", ignored);
  // A simulated robot's key is the closed session's own, made for its backend (now ended); the
  // next makes its own and never replaces a key it did not write.
  if (before.robot.backend == "simulated")
    std::filesystem::remove(options.folder / "robot.key", ignored);
  try {
    opened = openSession(*next, options, context);
    std::cerr << "\nsettings applied from the Settings panel: the session opened again\n";
  } catch (const std::exception& error) {
    std::cerr << "\nsettings not applied (" << error.what()
              << "); the session opened again with the settings it had\n";
    opened = openSession(before, options, context);
  }
}

}  // namespace

namespace {

// Where the panel layout is kept between runs.
std::string layoutFile() {
  const char* config = std::getenv("XDG_CONFIG_HOME");
  const char* home = std::getenv("HOME");
  std::filesystem::path dir = config ? std::filesystem::path(config)
                              : home ? std::filesystem::path(home) / ".config"
                                     : ".";
  dir /= "arbci";
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  return (dir / "layout.ini").string();
}

}  // namespace

int runWorkstation(const session::SessionConfig& config, session::SessionOptions options,
                   const WorkstationOptions& workstation) {
  // Read before the window opens: a bad script is refused at once.
  std::optional<ExperimenterScript> script;
  if (!workstation.script.empty()) script.emplace(workstation.script);
  const bool close_when_ended = workstation.close_when_ended;
  options.clock = session::Clock::Mode::RealTime;
  // Unattended (the timing check), a failed pre-flight ends the run as it does headless.
  options.experimenter = !workstation.unattended;
  options.presents_itself = false;  // the window's swap is the presentation
  render::WindowOptions window;
  window.title = "ARBCI workstation";
  // A headset's runtime paces the frames; the monitor's refresh must not pace them too.
  window.vsync = config.hmd.output != "openxr";
  render::WindowContext main_window(window);
  std::unique_ptr<render::WindowContext> mirror;
  const int monitors = render::WindowContext::monitorCount();
  if (config.hmd.mirror_monitor >= monitors) {
    // A pre-flight failure, shown in the window: the subject would see the HMD view nowhere.
    options.display_failures.push_back(
        "hmd.mirror_monitor = " + std::to_string(config.hmd.mirror_monitor) +
        ": there is no such monitor (this display has " + std::to_string(monitors) +
        (monitors == 1 ? " monitor: 0" : " monitors: 0 to " + std::to_string(monitors - 1)) +
        "; -1 for none)");
  } else if (config.hmd.mirror_monitor >= 0) {
    render::WindowOptions m;
    m.title = "ARBCI HMD";
    m.fullscreen_monitor = config.hmd.mirror_monitor;
    m.share_with = main_window.window();
    mirror = std::make_unique<render::WindowContext>(m);
    main_window.makeCurrent();
  }
  // A headset through its OpenXR runtime: opened on the main window's context (the HMD stage
  // draws there); what fails is the pre-flight's to say, in the window.
  std::optional<OpenXrOutput> xr;
  if (config.hmd.output == "openxr") {
    xr.emplace(config, main_window);
    if (!xr->open()) options.display_failures.push_back(xr->failure());
    main_window.makeCurrent();
  }
  ui::ImGuiLayer imgui(main_window, layoutFile());
  showOpening(main_window, imgui, config);
  OpenedSession opened = openSession(config, options, main_window);
  if (workstation.opened) workstation.opened();
  // The session the window runs: the start screen may open it again with other settings.
  session::Session* session = opened.session.get();
  // The X server gone (killed, logged out): Xlib would end the process where it stands. The run
  // ends as a fault and its summary is saved first (the recording and the log are written as
  // they go); exit 3, as for any run that did not finish.
  render::onDisplayLost(
      [&session](const std::string& reason) {
        session->endNow(reason);
        std::cerr << "\nended: fault (" << reason << "); " << session->folder().string()
                  << "/summary.json written\n";
      },
      3);
  // Unattended, the session starts itself.
  if (!workstation.wait_for_start && !workstation.unattended)
    session->request(session::StartRequest{});
  SessionRequests requests(*session, workstation.bids_root);
  const auto describe = [&](const core::RunLabels& labels) {
    return describeRun(labels, session->folder(), workstation.bids_root);
  };
  ui::WindowState state(describe);
  const auto attach = [&] {
    state.hmd_texture = opened.hmd->texture();
    state.hmd_aspect = static_cast<float>(session->config().hmd.width) /
                       static_cast<float>(session->config().hmd.height);
    state.ingest(session->last(), session->config());
  };
  attach();
  ui::ExperimenterShell shell;
  // Every registered panel, in the registry's order; the summary opens when the session ends.
  std::vector<std::unique_ptr<ui::Panel>> panels;
  ui::Panel* summary_panel = nullptr;
  ui::Panel* training_panel = nullptr;  // the calibration review is there
  bool reviewing = false, opened_for_review = false;
  for (const auto& entry : ui::panels().entries()) {
    panels.push_back(entry.make.make());
    shell.addPanel(*panels.back(), entry.make.open_at_start);
    if (entry.name == "summary") summary_panel = panels.back().get();
    if (entry.name == "training") training_panel = panels.back().get();
  }
  shell.showEmergencyStop(true);
  shell.setQuitHandler([&] { main_window.requestClose(); });
  // Ctrl+C or a TERM closes the window like the menu does: the session ends and saves its summary.
  watchInterrupts();
  auto last = std::chrono::steady_clock::now();
  bool summary_shown = false, interrupted = false;
  while (!main_window.shouldClose()) {
    // A script runs to its end first (its last screenshot may show the ended session).
    const bool script_over = !script || script->done();
    if (interruptRequested()) interrupted = true;
    if (interrupted || (close_when_ended && session->ended() && script_over))
      main_window.requestClose();
    render::WindowContext::pollEvents();
    main_window.makeCurrent();  // the simulated cameras render in it
    if (std::optional<nlohmann::json> settings = requests.takeSettings()) {
      reopen(opened, *settings, options, main_window);
      session = opened.session.get();
      requests.retarget(*session);
      state = ui::WindowState(describe);
      attach();
    }
    session->step();
    state.ingest(session->last(), session->config());
    // The calibration waits for the experimenter: its review opens in front (once per review).
    const bool review = session->last().paradigm.review.has_value();
    // Opened for it, it closes once answered: it would cover the panels the trials need.
    if (review && !reviewing && training_panel) {
      opened_for_review = !shell.isOpen(*training_panel);
      shell.show(*training_panel);
    }
    if (!review && reviewing && opened_for_review && training_panel) shell.hide(*training_panel);
    reviewing = review;
    if (session->ended() && !summary_shown) {
      if (summary_panel) shell.show(*summary_panel);  // once: the experimenter may close it
      summary_shown = true;
    }
    main_window.makeCurrent();
    const auto now = std::chrono::steady_clock::now();
    const float frame_ms = std::chrono::duration<float, std::milli>(now - last).count();
    last = now;
    const render::Size size = main_window.framebufferSize();
    const session::CycleRecord& record = session->last();
    const std::string phase = session::phaseText(record);
    ui::SyntheticInput input;
    if (script) {
      input = script->beforeFrame(bci::hostSeconds(), phase);
      if (const std::string panel = script->takePanelToOpen(); !panel.empty() && !shell.show(panel))
        std::cerr << "\nscript: no panel \"" << panel << "\" to open\n";
    }
    imgui.beginFrame(frame_ms / 1000.0f, script ? &input : nullptr);
    const ui::PanelInput panel_input{record, session->config(), session->operatorLog(), state,
                                     requests};
    shell.draw(
        size, {frame_ms, phase, session::statusLine(record, session->config(), state.cycleP50Ms())},
        panel_input);
    render::clearFramebuffer(0, size, {0.08f, 0.09f, 0.11f, 1.0f});
    imgui.endFrame();
    if (script) {
      script->afterFrame(main_window, size, session::phaseText(session->last()), session->time());
      if (!script->error().empty()) {
        std::cerr << "\nerror: " << script->error() << "\n";
        main_window.requestClose();
      }
    }
    // The subject's view is stamped at its own swap: the headset's predicted display time, the
    // HMD window's swap when there is one (its picture carries the photodiode patch), else the
    // experimenter window's, which shows it.
    const bool on_headset =
        xr && xr->present(*session, opened.hmd->texture(), opened.hmd->size(), true);
    if (on_headset) {
      main_window.makeCurrent();
      main_window.present();
    } else if (mirror) {
      mirror->makeCurrent();
      render::blitTexture(opened.hmd->texture(), opened.hmd->size(), mirror->framebufferSize());
      mirror->present();
      session->presented(bci::hostSeconds());  // the HMD's swap is done: its flashes are on screen
      main_window.makeCurrent();
      main_window.present();
    } else {
      main_window.present();
      session->presented(
          bci::hostSeconds());  // the swap is done: this frame's flashes are on screen
    }
  }
  // Quit (or the window closed) before the end: the run ends as an abort, saying who.
  if (!session->ended())
    session->abortNow(interrupted ? "interrupted (Ctrl+C or TERM)" : "by the experimenter (Quit)");
  if (script && !script->error().empty()) return 4;
  // Closed before the end: not finished.
  return session->ended() && session->endKind() == "finished" ? 0 : 3;
}

}  // namespace arbci::app
