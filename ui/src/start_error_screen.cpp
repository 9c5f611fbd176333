#include "arbci/ui/start_error_screen.h"

#include <imgui.h>

#include "arbci/ui/widget_registry.h"
#include "widgets.h"

namespace arbci::ui {

bool drawStartError(float width, float height, const std::string& message) {
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(width, height));
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;
  const char* title = "The session cannot start";
  ImGui::Begin(title, nullptr, flags);
  detail::recordWindow(title);
  ImGui::PushTextWrapPos(ImGui::GetContentRegionAvail().x);
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
  ImGui::TextUnformatted(message.c_str());
  ImGui::PopStyleColor();
  ImGui::Spacing();
  ImGui::TextUnformatted(
      "Nothing was recorded and no folder is kept. Fix what the message names (a session file's "
      "key is named as section.key: `arbci settings` lists every key with its range, and "
      "docs/settings.md documents them), then start the run again.");
  ImGui::PopTextWrapPos();
  ImGui::Spacing();
  const bool quit = button("Quit");
  ImGui::End();
  return quit;
}

}  // namespace arbci::ui
