#include <imgui.h>

#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "widgets.h"

namespace arbci::ui {

void emergencyStopButton(WorkstationModel& model) {
  if (stopButton("EMERGENCY STOP")) model.emergencyStop();
}

namespace {

// After an emergency stop or a robot fault: what the experimenter can do, each button disabled
// with the reason while it cannot go.
void recoveryButtons(WorkstationModel& model, bool latched) {
  using Action = WorkstationModel::Action;
  heading("recovery");
  if (button("Reset", latched ? "" : "no stop is latched")) model.robotReset();
  if (ImGui::IsItemHovered() && latched) ImGui::SetTooltip("lift the latched stop; nothing moves");
  ImGui::SameLine();
  if (button("Home", model.whyNot(Action::Home))) model.robotHome();
  ImGui::SameLine();
  if (button("Open gripper", model.whyNot(Action::OpenGripper))) model.openGripper();
  if (button("Retry step", model.whyNot(Action::RetryStep))) model.retryStep();
  ImGui::SameLine();
  if (button("Skip trial", model.whyNot(Action::SkipTrial))) model.skipTrial();
  ImGui::SameLine();
  if (button("End session", model.ended() ? "the session has ended" : "")) model.endSession();
}

}  // namespace

void RobotPanel::draw() {
  emergencyStopButton(model_);
  const auto status = model_.robotStatus();
  if (model_.ended()) {
    // The session no longer reads the robot link: what follows is the last status it got.
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.6f, 0.2f, 1.0f));
    ImGui::TextWrapped(
        "session ended: the robot is no longer watched; its last status before the "
        "end:");
    ImGui::PopStyleColor();
  } else if (model_.robotSilent()) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "backend silent: no answer for over a second");
  } else if (!status) {
    ImGui::TextDisabled("waiting for the backend's first status");
  } else {
    ImGui::TextColored(ImVec4(0.4f, 1, 0.4f, 1), "connected");
  }
  if (status && !status->stop_reason.empty()) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "STOPPED: %s", status->stop_reason.c_str());
    ImGui::TextWrapped(
        "Check the arm and the scene. Home parks it; Open gripper puts down what it holds where "
        "it was taken from; then Retry step, Skip trial, or End session (each lifts the stop).");
  }
  recoveryButtons(model_, status && !status->stop_reason.empty());
  if (status) {
    ImGui::Text("state: %s", robot::toString(status->state));
    if (status->current_command != robot::MessageType::Status) {
      ImGui::Text("command: %s #%llu", robot::toString(status->current_command),
                  static_cast<unsigned long long>(status->current_sequence));
      ImGui::ProgressBar(static_cast<float>(status->progress));
    } else {
      ImGui::TextDisabled("no command running");
    }
    ImGui::Text("tool: (%.3f, %.3f, %.3f) m", status->tool.x, status->tool.y, status->tool.z);
    ImGui::Text("gripper: %s (%.0f%% open)", status->gripper_opening > 0.5 ? "open" : "closed",
                status->gripper_opening * 100.0);
    ImGui::Text("holding: %s", status->holding >= 0
                                   ? ("object " + std::to_string(status->holding)).c_str()
                                   : "nothing");
    if (status->last_finished_sequence > 0) {
      ImGui::Text("last finished: #%llu %s %s",
                  static_cast<unsigned long long>(status->last_finished_sequence),
                  robot::toString(status->last_outcome), status->last_outcome_text.c_str());
    }
  }
  heading("messages");
  const auto log = model_.robotLog();
  ImGui::BeginChild("robot log", ImVec2(0, 0), true);
  for (auto it = log.rbegin(); it != log.rend(); ++it) {
    const bool bad =
        it->find("rejected") == 0 || it->find("failed") == 0 || it->find("silent") == 0;
    if (bad) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.5f, 0.3f, 1));
      ImGui::TextWrapped("%s", it->c_str());
      ImGui::PopStyleColor();
    } else {
      ImGui::TextWrapped("%s", it->c_str());
    }
  }
  ImGui::EndChild();
}

PanelRegistry::Entry robotPanel() {
  return {"robot",
          "the arm's state, command and progress, the gripper, recovery, the E-STOP",
          {[](const PanelContext& c) { return std::make_unique<RobotPanel>(c.model); }}};
}

}  // namespace arbci::ui
