// The experimenter window shell: menu bar, a panel area laid out in columns, and a status bar
// with the frame time.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "arbci/render/gl_context.h"
#include "arbci/ui/panel.h"

namespace arbci::ui {

struct ShellStatus {
  float frame_ms = 0.0f;      // time of the last displayed frame
  std::string session_state;  // e.g. "idle", "phase 1: sequence 3/10"
  std::string message;        // the latest notice for the experimenter
};

class ExperimenterShell {
 public:
  // Panels are shown in order; the shell does not own them.
  void addPanel(Panel& panel, bool open = true);
  void show(Panel& panel);  // opens a panel added closed (e.g. the end-of-session summary)
  bool show(const std::string& title);  // by its title; false when there is none
  void setQuitHandler(std::function<void()> on_quit) { on_quit_ = std::move(on_quit); }
  // An emergency stop button in the menu bar, shown whatever panels are open; `why_not` says why
  // it cannot act now ("" when it can).
  void setEmergencyStop(std::function<void()> on_stop, std::function<std::string()> why_not) {
    on_stop_ = std::move(on_stop);
    stop_why_not_ = std::move(why_not);
  }
  // Draws the whole shell for one frame; call between ImGuiLayer::beginFrame and endFrame.
  void draw(render::Size display, const ShellStatus& status);

 private:
  struct Entry {
    Panel* panel;
    bool open;
    bool at_start;  // open when the window opened: laid out in the columns
  };
  void drawMenuBar();
  void drawPanels(render::Size display, float top, float bottom);
  void fitToScreen(render::Size display, float top, float bottom);
  void drawStatusBar(render::Size display, float height, const ShellStatus& status);
  std::vector<Entry> panels_;
  std::function<void()> on_quit_, on_stop_;
  std::function<std::string()> stop_why_not_;
  bool show_about_ = false;
  bool reset_layout_ = false;
  Panel* focus_ = nullptr;  // brought to the front in the next frame
};

}  // namespace arbci::ui
