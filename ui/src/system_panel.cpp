#include "arbci/ui/system_panel.h"

#include <imgui.h>

namespace arbci::ui {

void SystemPanel::draw(const PanelInput& /*in*/) {
  if (ImGui::BeginTable("facts", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthFixed, 140.0f);
    ImGui::TableSetupColumn("value");
    for (const auto& [key, value] : facts_) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(key.c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", value.c_str());
    }
    ImGui::EndTable();
  }
}

}  // namespace arbci::ui
