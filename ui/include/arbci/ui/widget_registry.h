// The buttons the last frame drew: label, screen rectangle, whether enabled and, when not, why.
// A scripted experimenter (arbci run --script) finds a button here by its label and clicks it
// with real mouse input, so scripts exercise the same widgets a person does.
#pragma once

#include <string>
#include <vector>

namespace arbci::ui {

struct DrawnWidget {
  std::string label;   // as shown (without an ImGui "##id" suffix)
  std::string window;  // the panel (window) it is in
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool enabled = true;
  std::string why_disabled;
  bool clicked = false;  // a click landed on it in this frame (the UI acted on it)
};

// The widgets of the last frame that ended (ImGuiLayer::endFrame).
const std::vector<DrawnWidget>& drawnWidgets();
// The panels (windows) the last frame drew, by title.
const std::vector<std::string>& drawnWindows();

namespace detail {
void endWidgetFrame();  // ImGuiLayer, as each frame ends
void recordWidget(DrawnWidget widget);
void recordWindow(const std::string& title);
}  // namespace detail

}  // namespace arbci::ui
