// The operator log: everything the experimenter was told (ends, faults, refusals, pauses,
// warnings), with its session time, filterable by severity and by text.
#include <imgui.h>

#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

ImVec4 colour(OperatorLine::Severity severity) {
  switch (severity) {
    case OperatorLine::Severity::Error:
      return {1.0f, 0.35f, 0.3f, 1.0f};
    case OperatorLine::Severity::Warning:
      return {1.0f, 0.65f, 0.2f, 1.0f};
    case OperatorLine::Severity::Info:
      break;
  }
  return ImGui::GetStyle().Colors[ImGuiCol_Text];
}

}  // namespace

void OperatorLogPanel::draw() {
  // Read again only when something was said: the panel is drawn every frame.
  if (const size_t size = model_.operatorLogSize(); size != lines_.size()) {
    lines_ = model_.operatorLog();
    scroll_to_end_ = true;
  }
  ImGui::Checkbox("errors", &show_[2]);
  ImGui::SameLine();
  ImGui::Checkbox("warnings", &show_[1]);
  ImGui::SameLine();
  ImGui::Checkbox("information", &show_[0]);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(std::max(80.0f, ImGui::GetContentRegionAvail().x));
  ImGui::InputTextWithHint("##filter", "filter: text to find", filter_, sizeof filter_);
  ImGui::BeginChild("operator log lines", ImVec2(0, 0), true);
  int shown = 0;
  for (const OperatorLine& line : lines_) {
    if (!show_[static_cast<int>(line.severity)] || !containsIgnoringCase(line.text, filter_))
      continue;
    ++shown;
    ImGui::TextDisabled("%7.1f s", line.t);
    ImGui::SameLine();
    ImGui::PushStyleColor(ImGuiCol_Text, colour(line.severity));
    ImGui::TextWrapped("%s", line.text.c_str());
    ImGui::PopStyleColor();
  }
  if (shown == 0)
    ImGui::TextDisabled(lines_.empty() ? "nothing to report yet" : "no line matches the filter");
  if (scroll_to_end_) {
    ImGui::SetScrollHereY(1.0f);
    scroll_to_end_ = false;
  }
  ImGui::EndChild();
}

PanelRegistry::Entry operatorLogPanel() {
  return {"log",
          "the operator log: every end, fault, refusal, pause and warning with its time",
          {[](const PanelContext& c) { return std::make_unique<OperatorLogPanel>(c.model); }}};
}

}  // namespace arbci::ui
