// Small widgets the panels share.
#pragma once

#include <imgui.h>

namespace arbci::ui {

// A separator with a title under it (this ImGui has no SeparatorText).
inline void heading(const char* text) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::TextDisabled("%s", text);
}

}  // namespace arbci::ui
