// A scripted experimenter for the window (`arbci run --script FILE`): the script's lines are
// replayed frame by frame as real mouse and key input on the real widgets, so a study day's paths
// (an emergency stop, the recovery, the end) can be rehearsed and tested under Xvfb. One command
// per line; a label with spaces is quoted; # starts a comment:
//   wait "TEXT" [SECONDS]        until the session's phase (as the Session panel shows it)
//                                contains TEXT (default: at most 300 s)
//   click "LABEL" [SECONDS]      the button shown as LABEL, once it is drawn and enabled (the
//                                first of that label); a button still disabled at the time limit
//                                (default 60 s) fails the script with the button's reason
//   pause SECONDS                let the session run
//   key ctrl+q                   a key press (ctrl+LETTER or LETTER)
//   type "TEXT"                  in the field last clicked: its text replaced by TEXT, then Enter
//   open "PANEL"                 a panel opened as from the Panels menu (by its title)
//   screenshot FILE.png          the whole window as it is, and FILE.json: the session's phase,
//                                the panels drawn and every button with its state and reason
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arbci/render/gl_context.h"
#include "arbci/ui/imgui_layer.h"

namespace arbci::app {

class ExperimenterScript {
 public:
  // Reads and checks the whole script; throws std::runtime_error naming the line.
  explicit ExperimenterScript(const std::filesystem::path& file);

  // Before a frame: the input the frame gets. `now_s`: the wall clock (the session's stops when
  // it ends); `phase`: the session's phase as shown.
  ui::SyntheticInput beforeFrame(double now_s, const std::string& phase);
  // After the frame is drawn, before it is presented: screenshots.
  void afterFrame(render::GlContext& context, render::Size size, const std::string& phase,
                  double session_s);

  // A panel the script asked to open ("" when none), once: the window opens it.
  std::string takePanelToOpen() { return std::exchange(panel_to_open_, ""); }
  bool done() const { return next_ >= commands_.size() || !error_.empty(); }
  const std::string& error() const { return error_; }  // non-empty: the script failed

 private:
  struct Command {
    enum class Kind { Wait, Click, Pause, Key, Type, Open, Screenshot } kind;
    std::string text;  // the phase text, the label, the key or the file
    double seconds = 0.0;
    int line = 0;
  };
  void fail(const Command& command, const std::string& why);
  void advance();

  std::filesystem::path folder_;  // relative screenshot paths: the working folder
  std::vector<Command> commands_;
  size_t next_ = 0;
  double started_s_ = -1.0;  // when the current command began
  int click_stage_ = 0;      // 0: find, 1: press, 2: release, 3: confirm; type: 0-2
  std::string panel_to_open_;
  float click_x_ = 0, click_y_ = 0;
  std::string error_;
};

}  // namespace arbci::app
