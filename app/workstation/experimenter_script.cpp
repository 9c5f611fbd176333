#include "workstation/experimenter_script.h"

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/ui/widget_registry.h"
#include "support/png.h"

namespace arbci::app {
namespace {

// The line's words; a quoted one may hold spaces.
std::vector<std::string> words(const std::string& line, int number) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    if (std::isspace(static_cast<unsigned char>(line[i]))) {
      ++i;
      continue;
    }
    if (line[i] == '#') break;
    if (line[i] == '"') {
      const size_t end = line.find('"', i + 1);
      if (end == std::string::npos)
        throw std::runtime_error("line " + std::to_string(number) + ": a quote is not closed");
      out.push_back(line.substr(i + 1, end - i - 1));
      i = end + 1;
      continue;
    }
    size_t end = i;
    while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end]))) ++end;
    out.push_back(line.substr(i, end - i));
    i = end;
  }
  return out;
}

double secondsOf(const std::string& text, int number) {
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && v > 0.0 && v <= 3600.0) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error("line " + std::to_string(number) + ": '" + text +
                           "' is not a number of seconds between 0 and 3600");
}

}  // namespace

ExperimenterScript::ExperimenterScript(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot read the script");
  std::string line;
  int number = 0;
  using Kind = Command::Kind;
  while (std::getline(in, line)) {
    ++number;
    const std::vector<std::string> w = words(line, number);
    if (w.empty()) continue;
    auto need = [&](size_t least, size_t most) {
      if (w.size() < least || w.size() > most)
        throw std::runtime_error(file.string() + ": line " + std::to_string(number) + ": '" + w[0] +
                                 "' takes " + std::to_string(least - 1) + " to " +
                                 std::to_string(most - 1) + " arguments");
    };
    Command c{Kind::Wait, "", 0.0, number};
    if (w[0] == "wait") {
      need(2, 3);
      c = {Kind::Wait, w[1], w.size() > 2 ? secondsOf(w[2], number) : 300.0, number};
    } else if (w[0] == "click") {
      need(2, 3);
      c = {Kind::Click, w[1], w.size() > 2 ? secondsOf(w[2], number) : 60.0, number};
    } else if (w[0] == "pause") {
      need(2, 2);
      c = {Kind::Pause, "", secondsOf(w[1], number), number};
    } else if (w[0] == "key") {
      need(2, 2);
      std::string key = w[1];
      for (char& ch : key) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      const std::string letter = key.rfind("ctrl+", 0) == 0 ? key.substr(5) : key;
      if (letter.size() != 1 || !std::isalpha(static_cast<unsigned char>(letter[0])))
        throw std::runtime_error(file.string() + ": line " + std::to_string(number) +
                                 ": a key is a letter or ctrl+letter, got '" + w[1] + "'");
      c = {Kind::Key, key, 0.0, number};
    } else if (w[0] == "type") {
      need(2, 2);
      c = {Kind::Type, w[1], 0.0, number};
    } else if (w[0] == "open") {
      need(2, 2);
      c = {Kind::Open, w[1], 0.0, number};
    } else if (w[0] == "screenshot") {
      need(2, 2);
      if (std::filesystem::path(w[1]).extension() != ".png")
        throw std::runtime_error(file.string() + ": line " + std::to_string(number) +
                                 ": a screenshot is a .png file");
      c = {Kind::Screenshot, w[1], 0.0, number};
    } else {
      throw std::runtime_error(file.string() + ": line " + std::to_string(number) +
                               ": unknown command '" + w[0] +
                               "' (wait, click, pause, key, type, open, screenshot)");
    }
    commands_.push_back(c);
  }
}

void ExperimenterScript::fail(const Command& command, const std::string& why) {
  error_ = "script line " + std::to_string(command.line) + ": " + why;
}

void ExperimenterScript::advance() {
  ++next_;
  started_s_ = -1.0;  // the next command's time starts at its first frame
  click_stage_ = 0;
}

ui::SyntheticInput ExperimenterScript::beforeFrame(double now_s, const std::string& phase) {
  ui::SyntheticInput input;
  input.x = input.y = -FLT_MAX;  // no pointer over the window
  if (done()) return input;
  if (started_s_ < 0.0) started_s_ = now_s;
  const Command& c = commands_[next_];
  const double waited = now_s - started_s_;
  using Kind = Command::Kind;
  switch (c.kind) {
    case Kind::Wait:
      if (phase.find(c.text) != std::string::npos) {
        std::cerr << "\nscript: \"" << c.text << "\" after " << waited << " s\n";
        advance();
      } else if (waited > c.seconds) {
        fail(c, "waited " + std::to_string(static_cast<int>(c.seconds)) + " s for \"" + c.text +
                    "\"; the phase is \"" + phase + "\"");
      }
      break;
    case Kind::Pause:
      if (waited >= c.seconds) advance();
      break;
    case Kind::Key:
      input.ctrl = c.text.rfind("ctrl+", 0) == 0;
      input.key = std::toupper(static_cast<unsigned char>(c.text.back()));  // GLFW's letter codes
      advance();
      break;
    case Kind::Type:
      // Select all (Ctrl+A), type, Enter: one frame each.
      if (click_stage_ == 0) {
        input.ctrl = true;
        input.key = 'A';
      } else if (click_stage_ == 1) {
        input.text = c.text;
      } else {
        input.key = 257;  // GLFW_KEY_ENTER
      }
      if (++click_stage_ > 2) advance();
      break;
    case Kind::Open:
      panel_to_open_ = c.text;
      advance();
      break;
    case Kind::Click: {
      const ui::DrawnWidget* found = nullptr;
      for (const ui::DrawnWidget& w : ui::drawnWidgets()) {
        if (w.label == c.text) {
          found = &w;
          break;
        }
      }
      const float x = found ? 0.5f * (found->x0 + found->x1) : 0.0f;
      const float y = found ? 0.5f * (found->y0 + found->y1) : 0.0f;
      // The panel's layout can shift under the pointer (a message appears above the button):
      // the click starts again wherever the button is now.
      if (click_stage_ > 0 && click_stage_ < 3 &&
          (!found || !found->enabled || std::abs(x - click_x_) > 1.0f ||
           std::abs(y - click_y_) > 1.0f)) {
        click_stage_ = 0;
      }
      if (click_stage_ == 0) {
        if (found && found->enabled) {
          click_x_ = x;
          click_y_ = y;
          click_stage_ = 1;
        } else if (waited > c.seconds) {
          fail(c, found ? "\"" + c.text + "\" stayed disabled: " + found->why_disabled
                        : "no button \"" + c.text + "\" was drawn");
          break;
        }
        input.x = click_x_;
        input.y = click_y_;
        break;
      }
      // Pointer there (one frame), pressed (one frame), released (one frame): ImGui's click.
      // Then the frame that took the release says whether it landed: the layout can shift in
      // that very frame (a message appears above the button as the arm reports), and the release
      // then falls beside the button and nothing happens; the click is made again.
      input.x = click_x_;
      input.y = click_y_;
      input.left_down = click_stage_ == 1;
      if (click_stage_ == 3) {
        const bool landed =
            std::any_of(ui::drawnWidgets().begin(), ui::drawnWidgets().end(),
                        [&](const ui::DrawnWidget& w) { return w.label == c.text && w.clicked; });
        if (landed) {
          std::cerr << "\nscript: clicked \"" << c.text << "\"\n";
          advance();
        } else {
          std::cerr << "\nscript: the click on \"" << c.text
                    << "\" fell beside it (the panel moved); clicking again\n";
          click_stage_ = 0;
        }
      } else {
        ++click_stage_;
      }
      break;
    }
    case Kind::Screenshot:
      break;  // taken after the frame is drawn
  }
  return input;
}

void ExperimenterScript::afterFrame(render::GlContext& context, render::Size size,
                                    const std::string& phase, double session_s) {
  if (done() || commands_[next_].kind != Command::Kind::Screenshot) return;
  const Command& c = commands_[next_];
  try {
    writePng(c.text, render::readPixels(context.drawFramebuffer(), size));
    nlohmann::json buttons = nlohmann::json::array();
    for (const ui::DrawnWidget& w : ui::drawnWidgets()) {
      buttons.push_back({{"label", w.label},
                         {"panel", w.window},
                         {"enabled", w.enabled},
                         {"why_disabled", w.why_disabled},
                         {"rect", {w.x0, w.y0, w.x1, w.y1}}});
    }
    std::filesystem::path sidecar = c.text;
    sidecar.replace_extension(".json");
    std::ofstream(sidecar) << nlohmann::json{{"phase", phase},
                                             {"session_time_s", session_s},
                                             {"size", {size.width, size.height}},
                                             {"panels", ui::drawnWindows()},
                                             {"buttons", buttons}}
                                  .dump(2)
                           << "\n";
    std::cerr << "\nscript: screenshot " << c.text << "\n";
  } catch (const std::exception& e) {
    fail(c, e.what());
    return;
  }
  advance();
}

}  // namespace arbci::app
