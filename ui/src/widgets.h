// Small widgets the panels share.
#pragma once

#include <imgui.h>

#include <string>

namespace arbci::ui {

struct PanelInput;

// A separator with a title under it (this ImGui has no SeparatorText).
inline void heading(const char* text) {
  ImGui::Spacing();
  ImGui::Separator();
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("%s", text);  // never cut in a narrow panel
  ImGui::PopStyleColor();
}

// Wrapped text in a colour (a warning, a reason).
inline void colouredWrapped(const ImVec4& colour, const std::string& text) {
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

// A button that says why it cannot be pressed: with `why_not` non-empty it is drawn disabled and
// hovering it shows the reason. Every press leaves visible feedback this way (it acts, or it
// says why not). Recorded for scripted clicks (widget_registry.h). Returns true when pressed.
bool button(const char* label, const std::string& why_not = "", bool small = false);

// Whether `text` holds `needle`, ignoring case (the panels' filter boxes); an empty needle: yes.
bool containsIgnoringCase(const std::string& text, const std::string& needle);

// Records the last item (a text or number field) under `label`, for a scripted click to find it
// (widget_registry.h); "clicked" there means the field took the keyboard.
// `width`: the field's own (its label beside it is not part of what a click should hit).
void recordField(const std::string& label, float width);
// The same for a combo, called right after ImGui::BeginCombo with what it returned: "clicked"
// there means its list is open.
void recordCombo(const std::string& label, float width, bool open);

// The same, in the emergency stop's red.
bool stopButton(const char* label, bool small = false, const std::string& why_not = "");

// The emergency stop, as every panel that offers it shows it: posts the request (the session
// sends the arm its STOP at once), or says why it cannot.
void emergencyStopButton(const PanelInput& in);

// A button whose action is asked about first: pressing it opens a dialog with `question` and
// a button `yes` (and Cancel). Returns true when `yes` is pressed. The button stays where it is
// whatever the state; `why_not` disables it as button() does.
bool confirmedButton(const char* label, const std::string& why_not, const std::string& question,
                     const char* yes);

// A path typed by hand, with a Browse list of the folder's files beside it (those ending in one
// of `extensions`, e.g. ".bdf .dat .gdf"). Returns true when the path changed.
bool pathInput(const char* label, char* path, size_t size, const char* extensions,
               const char* tooltip);

}  // namespace arbci::ui
