#include "arbci/ui/experimenter_shell.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "arbci/session/experimenter.h"
#include "arbci/ui/widget_registry.h"
#include "widgets.h"

namespace arbci::ui {
namespace {
constexpr ImGuiWindowFlags kBarFlags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                       ImGuiWindowFlags_NoSavedSettings |
                                       ImGuiWindowFlags_NoBringToFrontOnFocus;
}

void ExperimenterShell::addPanel(Panel& panel, bool open) {
  panels_.push_back({&panel, open, open});
}

void ExperimenterShell::show(Panel& panel) {
  for (Entry& entry : panels_) {
    if (entry.panel == &panel) entry.open = true;
  }
}

void ExperimenterShell::hide(Panel& panel) {
  for (Entry& entry : panels_) {
    if (entry.panel == &panel) entry.open = false;
  }
}

bool ExperimenterShell::isOpen(const Panel& panel) const {
  for (const Entry& entry : panels_) {
    if (entry.panel == &panel) return entry.open;
  }
  return false;
}

bool ExperimenterShell::show(const std::string& title) {
  for (Entry& entry : panels_) {
    if (title == entry.panel->title()) {
      entry.open = true;
      focus_ = entry.panel;  // in front, as a menu's choice would be
      return true;
    }
  }
  return false;
}

void ExperimenterShell::draw(render::Size display, const ShellStatus& status,
                             const PanelInput& in) {
  drawMenuBar(in);
  const float menu_height = ImGui::GetFrameHeight();
  const float status_height = ImGui::GetFrameHeight() + 6.0f;
  drawPanels(display, menu_height, static_cast<float>(display.height) - status_height, in);
  drawStatusBar(display, status_height, status);
  if (show_about_) {
    ImGui::OpenPopup("About ARBCI");
    show_about_ = false;
  }
  drawQuit(in);
  if (ImGui::BeginPopupModal("About ARBCI", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::Text("ARBCI %s", ARBCI_VERSION);
    ImGui::TextUnformatted("Augmented-reality BCI experimenter workstation.");
    if (ImGui::Button("Close")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
}

// Quitting ends a running session as Abort does: it asks the same question first. Before the
// start or after the end there is nothing to lose, and it quits at once.
void ExperimenterShell::drawQuit(const PanelInput& in) {
  if (quit_asked_) {
    quit_asked_ = false;
    const bool running = in.record.paradigm.phase != bci::Phase::Setup && !in.record.ended;
    if (!running) {
      if (on_quit_) on_quit_();
      return;
    }
    ImGui::OpenPopup("Quit ARBCI?##confirm");
  }
  if (!ImGui::BeginPopupModal("Quit ARBCI?##confirm", nullptr, ImGuiWindowFlags_AlwaysAutoResize))
    return;
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
  ImGui::TextUnformatted(
      "The session is running. Quitting ends it now (as Abort does); what was recorded is kept.");
  ImGui::PopTextWrapPos();
  if (button("Yes, quit")) {
    ImGui::CloseCurrentPopup();
    if (on_quit_) on_quit_();
  }
  ImGui::SameLine();
  if (button("Cancel")) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

void ExperimenterShell::drawMenuBar(const PanelInput& in) {
  // Ctrl+Q, as the menu says. This ImGui (1.86) indexes keys by the backend's codes; GLFW's for
  // letters are their upper-case ASCII codes.
  const bool quit = ImGui::GetIO().KeyCtrl && ImGui::IsKeyPressed('Q', false);
  if (quit) quit_asked_ = true;
  if (!ImGui::BeginMainMenuBar()) return;
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("Quit", "Ctrl+Q")) quit_asked_ = true;
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Panels")) {
    for (Entry& entry : panels_) ImGui::MenuItem(entry.panel->title(), nullptr, &entry.open);
    ImGui::Separator();
    // Every open panel back to the default columns (the saved layout is replaced on exit).
    if (ImGui::MenuItem("Reset layout")) reset_layout_ = true;
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Help")) {
    if (ImGui::MenuItem("About")) show_about_ = true;
    ImGui::EndMenu();
  }
  if (show_stop_) {
    ImGui::SameLine(ImGui::GetWindowWidth() - 170.0f);
    if (stopButton("EMERGENCY STOP", true,
                   session::whyNot(session::Action::EmergencyStop, in.record)))
      in.requests.post(session::EmergencyStopRequest{});
  }
  ImGui::EndMainMenuBar();
}

void ExperimenterShell::drawPanels(render::Size display, float top, float bottom,
                                   const PanelInput& in) {
  // Default layout (first run): the panels open at start side by side in up to three columns;
  // one opened later from the menu comes in front, large, over the middle of the window.
  std::vector<Entry*> open;
  for (Entry& entry : panels_) {
    if (entry.open) open.push_back(&entry);
  }
  int at_start = 0;
  for (const Entry& entry : panels_) at_start += entry.at_start;
  if (open.empty()) return;
  const int count = static_cast<int>(open.size());
  const int columns = std::clamp(at_start, 1, 3);
  const int rows = std::max(1, (at_start + columns - 1) / columns);
  const float width = static_cast<float>(display.width) / static_cast<float>(columns);
  const float height = (bottom - top) / static_cast<float>(rows);
  const ImGuiCond when = reset_layout_ ? ImGuiCond_Always : ImGuiCond_FirstUseEver;
  reset_layout_ = false;
  int slot = 0;
  for (int i = 0; i < count; ++i) {
    if (open[i]->at_start) {
      const float x = width * static_cast<float>(slot % columns);
      const float y = top + height * static_cast<float>(slot / columns);
      ++slot;
      ImGui::SetNextWindowPos(ImVec2(x, y), when);
      ImGui::SetNextWindowSize(ImVec2(width, height), when);
    } else {
      const float w = static_cast<float>(display.width);
      ImGui::SetNextWindowPos(ImVec2(w * 0.2f, top + (bottom - top) * 0.1f), when);
      ImGui::SetNextWindowSize(ImVec2(w * 0.6f, (bottom - top) * 0.8f), when);
    }
    if (focus_ == open[i]->panel) {
      ImGui::SetNextWindowFocus();
      focus_ = nullptr;
    }
    if (ImGui::Begin(open[i]->panel->title(), &open[i]->open)) {
      fitToScreen(display, top, bottom);
      detail::recordWindow(open[i]->panel->title());
      open[i]->panel->draw(in);
    }
    ImGui::End();
  }
}

void ExperimenterShell::fitToScreen(render::Size display, float top, float bottom) {
  // A layout saved on a larger screen (or a window made smaller) would leave panels, and their
  // buttons, out of reach: each is moved, then shrunk, to lie between the bars.
  const ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  const float screen_w = static_cast<float>(display.width), area_h = bottom - top;
  if (screen_w <= 0.0f || area_h <= 0.0f) return;
  const ImVec2 fitted_size(std::min(size.x, screen_w), std::min(size.y, area_h));
  const ImVec2 fitted_pos(std::clamp(pos.x, 0.0f, screen_w - fitted_size.x),
                          std::clamp(pos.y, top, bottom - fitted_size.y));
  if (fitted_size.x != size.x || fitted_size.y != size.y) ImGui::SetWindowSize(fitted_size);
  if (fitted_pos.x != pos.x || fitted_pos.y != pos.y) ImGui::SetWindowPos(fitted_pos);
}

void ExperimenterShell::drawStatusBar(render::Size display, float height,
                                      const ShellStatus& status) {
  ImGui::SetNextWindowPos(ImVec2(0.0f, static_cast<float>(display.height) - height));
  ImGui::SetNextWindowSize(ImVec2(static_cast<float>(display.width), height));
  if (ImGui::Begin("##status", nullptr, kBarFlags)) {
    const float fps = status.frame_ms > 0.0f ? 1000.0f / status.frame_ms : 0.0f;
    ImGui::Text("frame %.1f ms (%.0f fps)", status.frame_ms, std::round(fps));
    if (!status.session_state.empty()) {
      ImGui::SameLine(0.0f, 30.0f);
      ImGui::Text("session: %s", status.session_state.c_str());
    }
    if (!status.message.empty()) {
      ImGui::SameLine(0.0f, 30.0f);
      ImGui::TextUnformatted(status.message.c_str());
    }
  }
  ImGui::End();
}

}  // namespace arbci::ui
