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
  void hide(Panel& panel);                // closes it, as its window's close button does
  bool isOpen(const Panel& panel) const;
  void setQuitHandler(std::function<void()> on_quit) { on_quit_ = std::move(on_quit); }
  // An emergency stop button in the menu bar, shown whatever panels are open (it posts the
  // request, or says why it cannot act now).
  void showEmergencyStop(bool show) { show_stop_ = show; }
  // Draws the whole shell for one frame, the panels over `in`; call between
  // ImGuiLayer::beginFrame and endFrame.
  void draw(render::Size display, const ShellStatus& status, const PanelInput& in);

 private:
  struct Entry {
    Panel* panel;
    bool open;
    bool at_start;  // open when the window opened: laid out in the columns
  };
  void drawMenuBar(const PanelInput& in);
  void drawQuit(const PanelInput& in);
  void drawPanels(render::Size display, float top, float bottom, const PanelInput& in);
  void fitToScreen(render::Size display, float top, float bottom);
  void drawStatusBar(render::Size display, float height, const ShellStatus& status);
  std::vector<Entry> panels_;
  std::function<void()> on_quit_;
  bool show_stop_ = false;
  bool show_about_ = false;
  bool quit_asked_ = false;  // Ctrl+Q or File > Quit, to be confirmed while a session runs
  bool reset_layout_ = false;
  Panel* focus_ = nullptr;  // brought to the front in the next frame
};

}  // namespace arbci::ui
