// The operator log: everything the experimenter was told (ends, faults, refusals, pauses,
// warnings), with its session time, filterable by severity and by text.
#include <imgui.h>

#include "arbci/ui/panel_registry.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

using session::Severity;

ImVec4 colour(Severity severity) {
  switch (severity) {
    case Severity::Error:
      return {1.0f, 0.35f, 0.3f, 1.0f};
    case Severity::Warning:
      return {1.0f, 0.65f, 0.2f, 1.0f};
    case Severity::Info:
      break;
  }
  return ImGui::GetStyle().Colors[ImGuiCol_Text];
}

class OperatorLogPanel final : public Panel {
 public:
  const char* title() const override { return "Operator log"; }
  void draw(const PanelInput& in) override;

 private:
  size_t seen_ = 0;                    // lines of the log when last drawn
  bool show_[3] = {true, true, true};  // by session::Severity
  char filter_[128] = "";
  bool scroll_to_end_ = false;
};

void OperatorLogPanel::draw(const PanelInput& in) {
  const std::vector<session::OperatorMessage>& lines = in.log.messages();
  // Scrolled to the end when something new was said.
  if (lines.size() != seen_) {
    seen_ = lines.size();
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
  for (const session::OperatorMessage& line : lines) {
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
    ImGui::TextDisabled(lines.empty() ? "nothing to report yet" : "no line matches the filter");
  if (scroll_to_end_) {
    ImGui::SetScrollHereY(1.0f);
    scroll_to_end_ = false;
  }
  ImGui::EndChild();
}

}  // namespace

PanelRegistry::Entry operatorLogPanel() {
  PanelParts parts{[] { return std::make_unique<OperatorLogPanel>(); }};
  parts.shots.push_back(
      {"log", "once the classifier is trained", [](const session::CycleRecord& r) {
         return r.paradigm.phase == bci::Phase::ObjectFlashing;
       }});
  return {"log", "the operator log: every end, fault, refusal, pause and warning with its time",
          std::move(parts)};
}

}  // namespace arbci::ui
