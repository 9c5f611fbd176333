// The Robot panel: connection, state, current command and progress, tool position, what the
// gripper holds, errors, the recovery after a stop, and the emergency stop.
#include <imgui.h>

#include "arbci/session/experimenter.h"
#include "arbci/ui/panel_registry.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

using session::Action;

// End session, asked first; with an object in the gripper the dialog offers to put it back
// before the end (once ended, the session no longer drives the arm).
void endSessionButton(const PanelInput& in) {
  const session::CycleRecord& r = in.record;
  const int held = r.robot.holding().value_or(-1);
  const std::string why_not = whyNot(Action::EndSession, r);
  if (button("End session", why_not)) ImGui::OpenPopup("End session?##confirm");
  if (!ImGui::BeginPopupModal("End session?##confirm", nullptr, ImGuiWindowFlags_AlwaysAutoResize))
    return;
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
  if (held >= 0) {
    ImGui::Text(
        "The gripper holds object %d. Once the session ends it no longer drives the arm: put the "
        "object back first (Open gripper puts it where it was taken from), then end.",
        held);
  } else {
    ImGui::TextUnformatted("End the session now? What was recorded is kept.");
  }
  ImGui::PopTextWrapPos();
  const std::string why_not_release = whyNot(Action::OpenGripper, r);
  if (held >= 0 && !why_not_release.empty()) {
    // Said here, not only on the disabled button's tooltip: what comes first.
    colouredWrapped(ImVec4(1.0f, 0.7f, 0.3f, 1.0f),
                    "Put it back first is not possible now (" + why_not_release +
                        "): press E-STOP to stop the trial, then put it back.");
  }
  if (held >= 0) {
    if (button("Put it back first", why_not_release)) {
      in.requests.post(session::RobotReleaseRequest{r.time_s});
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (button("End now")) {
      in.requests.post(session::EndSessionRequest{});
      ImGui::CloseCurrentPopup();
    }
  } else if (button("End now")) {
    in.requests.post(session::EndSessionRequest{});
    ImGui::CloseCurrentPopup();
  }
  ImGui::SameLine();
  if (button("Cancel")) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

// After an emergency stop or a robot fault: what the experimenter can do, each button disabled
// with the reason while it cannot go.
void recoveryButtons(const PanelInput& in, bool latched) {
  const session::CycleRecord& r = in.record;
  const double t = r.time_s;
  heading("recovery");
  const std::string why_not_reset = whyNot(Action::ResetRobot, r);
  if (button("Reset", !why_not_reset.empty() ? why_not_reset : latched ? "" : "no stop is latched"))
    in.requests.post(session::RobotResetRequest{t});
  if (ImGui::IsItemHovered() && latched) ImGui::SetTooltip("lift the latched stop; nothing moves");
  ImGui::SameLine();
  if (button("Home", whyNot(Action::Home, r))) in.requests.post(session::RobotHomeRequest{t});
  ImGui::SameLine();
  if (button("Open gripper", whyNot(Action::OpenGripper, r)))
    in.requests.post(session::RobotReleaseRequest{t});
  if (button("Retry step", whyNot(Action::RetryStep, r)))
    in.requests.post(session::RetryStepRequest{});
  ImGui::SameLine();
  if (button("Skip trial", whyNot(Action::SkipTrial, r)))
    in.requests.post(session::SkipTrialRequest{});
  ImGui::SameLine();
  endSessionButton(in);
}

void drawStatus(const robot::StatusPayload& status) {
  ImGui::Text("state: %s", robot::toString(status.state));
  if (status.current_command != robot::MessageType::Status) {
    ImGui::Text("command: %s #%llu", robot::toString(status.current_command),
                static_cast<unsigned long long>(status.current_sequence));
    ImGui::ProgressBar(static_cast<float>(status.progress));
  } else {
    ImGui::TextDisabled("no command running");
  }
  ImGui::Text("tool: (%.3f, %.3f, %.3f) m", status.tool.x, status.tool.y, status.tool.z);
  ImGui::Text("gripper: %s (%.0f%% open)", status.gripper_opening > 0.5 ? "open" : "closed",
              status.gripper_opening * 100.0);
  ImGui::Text("holding: %s", status.holding >= 0
                                 ? ("object " + std::to_string(status.holding)).c_str()
                                 : "nothing");
  if (status.last_finished_sequence > 0) {
    ImGui::Text("last finished: #%llu %s %s",
                static_cast<unsigned long long>(status.last_finished_sequence),
                robot::toString(status.last_outcome), status.last_outcome_text.c_str());
  }
}

void drawMessages(const std::vector<std::string>& log) {
  heading("messages");
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

class RobotPanel final : public Panel {
 public:
  const char* title() const override { return "Robot"; }
  void draw(const PanelInput& in) override;
};

void RobotPanel::draw(const PanelInput& in) {
  emergencyStopButton(in);
  const session::CycleRecord& r = in.record;
  const auto& status = r.robot.status;
  // One line whatever the state, and the STOPPED banner below the buttons: the recovery buttons
  // never move under the pointer when the state changes.
  if (r.ended) {
    // The session no longer reads the robot link: what follows is the last status it got.
    ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.2f, 1.0f),
                       "session ended: its last status of the robot");
  } else if (r.robot.silent) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "backend silent: no answer for over a second");
  } else if (!status) {
    ImGui::TextDisabled("waiting for the backend's first status");
  } else {
    ImGui::TextColored(ImVec4(0.4f, 1, 0.4f, 1), "connected");
  }
  recoveryButtons(in, status && !status->stop_reason.empty());
  if (status && !status->stop_reason.empty()) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1), "STOPPED: %s", status->stop_reason.c_str());
    ImGui::TextWrapped(
        "Check the arm and the scene. Home parks it; Open gripper puts down what it holds where "
        "it was taken from; then Retry step, Skip trial, or End session (each lifts the stop).");
  }
  if (status) drawStatus(*status);
  drawMessages(r.robot.messages ? *r.robot.messages : std::vector<std::string>{});
}

PanelParts robotParts() {
  PanelParts parts{[] { return std::make_unique<RobotPanel>(); }};
  parts.shots.push_back({"robot", "during the first grasp", [](const session::CycleRecord& r) {
                           return r.paradigm.phase == bci::Phase::Grasping && r.robot.status &&
                                  r.robot.status->progress > 0.3;
                         }});
  return parts;
}

}  // namespace

PanelRegistry::Entry robotPanel() {
  return {"robot", "the arm's state, command and progress, the gripper, recovery, the E-STOP",
          robotParts()};
}

}  // namespace arbci::ui
