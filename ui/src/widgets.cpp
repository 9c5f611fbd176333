#include "widgets.h"

#include <imgui_internal.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

#include "arbci/session/experimenter.h"
#include "arbci/ui/panel.h"
#include "arbci/ui/widget_registry.h"

namespace arbci::ui {
namespace {

std::string shownLabel(const char* label) {
  const std::string text = label;
  return text.substr(0, text.find("##"));
}

// The window's title as the experimenter sees it (ImGui keeps it with any "##" suffix).
std::string currentWindowTitle() {
  const ImGuiWindow* window = ImGui::GetCurrentWindowRead();
  return window ? shownLabel(window->Name) : std::string();
}

void record(const char* label, bool enabled, const std::string& why_not, bool clicked) {
  const ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
  detail::recordWidget({shownLabel(label), currentWindowTitle(), min.x, min.y, max.x, max.y,
                        enabled, why_not, clicked});
}

bool hasExtension(const std::filesystem::path& path, const char* extensions) {
  std::istringstream list(extensions);
  std::string ext;
  std::string have = path.extension().string();
  std::transform(have.begin(), have.end(), have.begin(), ::tolower);
  while (list >> ext) {
    if (have == ext) return true;
  }
  return false;
}

}  // namespace

bool button(const char* label, const std::string& why_not, bool small) {
  const bool enabled = why_not.empty();
  ImGui::BeginDisabled(!enabled);
  const bool pressed = small ? ImGui::SmallButton(label) : ImGui::Button(label);
  ImGui::EndDisabled();
  if (!enabled && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("%s", why_not.c_str());
  record(label, enabled, why_not, pressed && enabled);
  return pressed && enabled;
}

bool containsIgnoringCase(const std::string& text, const std::string& needle) {
  return std::search(text.begin(), text.end(), needle.begin(), needle.end(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) ==
                  std::tolower(static_cast<unsigned char>(b));
         }) != text.end();
}

void recordField(const std::string& label, float width) {
  const ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
  detail::recordWidget({label, currentWindowTitle(), min.x, min.y, std::min(max.x, min.x + width),
                        max.y, true, "", ImGui::IsItemActive()});
}

void recordCombo(const std::string& label, float width, bool open) {
  const ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
  detail::recordWidget({label, currentWindowTitle(), min.x, min.y, std::min(max.x, min.x + width),
                        max.y, true, "", open});
}

bool stopButton(const char* label, bool small, const std::string& why_not) {
  // Red only while it can stop the arm: a disabled one in red (ImGui only fades it) reads as
  // armed after the session has ended.
  ImGui::PushStyleColor(ImGuiCol_Button, why_not.empty() ? ImVec4(0.75f, 0.05f, 0.05f, 1.0f)
                                                         : ImVec4(0.35f, 0.22f, 0.22f, 1.0f));
  ImGui::PushStyleColor(ImGuiCol_ButtonHovered, ImVec4(0.95f, 0.1f, 0.1f, 1.0f));
  const bool pressed = button(label, why_not, small);
  ImGui::PopStyleColor(2);
  return pressed;
}

bool confirmedButton(const char* label, const std::string& why_not, const std::string& question,
                     const char* yes) {
  const std::string popup = shownLabel(label) + "?##confirm";
  if (button(label, why_not)) ImGui::OpenPopup(popup.c_str());
  bool confirmed = false;
  if (ImGui::BeginPopupModal(popup.c_str(), nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
    ImGui::TextUnformatted(question.c_str());
    ImGui::PopTextWrapPos();
    if (button(yes)) {
      confirmed = true;
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (button("Cancel")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
  return confirmed;
}

bool pathInput(const char* label, char* path, size_t size, const char* extensions,
               const char* tooltip) {
  namespace fs = std::filesystem;
  ImGui::PushID(label);
  ImGui::TextWrapped("%s", label);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip);
  const float browse_width = ImGui::CalcTextSize("Browse").x + 2 * ImGui::GetStyle().FramePadding.x;
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - browse_width -
                          ImGui::GetStyle().ItemSpacing.x);
  bool changed = ImGui::InputText("##path", path, size);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tooltip);
  ImGui::SameLine();
  if (button("Browse")) ImGui::OpenPopup("browse");
  if (ImGui::BeginPopup("browse")) {
    // The folder of what is typed (the last of a space-separated list), or the working folder.
    std::string typed = path;
    const size_t space = typed.find_last_of(' ');
    const std::string head = space == std::string::npos ? "" : typed.substr(0, space + 1);
    const std::string last = space == std::string::npos ? typed : typed.substr(space + 1);
    std::error_code error;
    fs::path folder = last.empty() ? fs::current_path(error) : fs::path(last);
    if (!fs::is_directory(folder, error)) folder = folder.parent_path();
    if (folder.empty()) folder = fs::current_path(error);
    ImGui::TextDisabled("%s", folder.string().c_str());
    std::vector<fs::directory_entry> entries;
    for (const auto& entry : fs::directory_iterator(folder, error)) entries.push_back(entry);
    std::sort(entries.begin(), entries.end());
    auto choose = [&](const std::string& chosen) {
      std::snprintf(path, size, "%s%s", head.c_str(), chosen.c_str());
      changed = true;
    };
    if (ImGui::Selectable("..", false, ImGuiSelectableFlags_DontClosePopups))
      choose(fs::absolute(folder / "..", error).lexically_normal().string() + "/");
    for (const auto& entry : entries) {
      const std::string name = entry.path().filename().string();
      if (entry.is_directory(error)) {
        if (ImGui::Selectable((name + "/").c_str(), false, ImGuiSelectableFlags_DontClosePopups))
          choose(entry.path().string() + "/");
      } else if (hasExtension(entry.path(), extensions)) {
        if (ImGui::Selectable(name.c_str())) choose(entry.path().string());
      }
    }
    if (entries.empty()) ImGui::TextDisabled("(empty or unreadable)");
    ImGui::EndPopup();
  }
  ImGui::PopID();
  return changed;
}

void emergencyStopButton(const PanelInput& in) {
  if (stopButton("EMERGENCY STOP", false,
                 session::whyNot(session::Action::EmergencyStop, in.record)))
    in.requests.post(session::EmergencyStopRequest{});
}

}  // namespace arbci::ui
