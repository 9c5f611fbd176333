#include <imgui.h>

#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "widgets.h"

#include <cstdio>
#include <string>

namespace arbci::ui {
namespace {
std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}
}  // namespace

void SessionPanel::draw() {
  using Action = WorkstationModel::Action;
  // One line (a narrow panel cuts it; the reason below wraps): the buttons stay where they are.
  ImGui::Text("%s", model_.phase().c_str());
  ImGui::Text("trial %d of %d, sequence %d, session time %.1f s", model_.trial(), model_.trials(),
              model_.sequence(), model_.sessionTime());
  // Every button in its own place whatever the state (disabled with its reason where it cannot
  // act): a double click never lands on a button that took another's place.
  if (!labels_read_) readLabels();
  const std::string& labels_problem = model_.started() ? std::string() : labels_problem_;
  if (button("Start", !labels_problem.empty() ? labels_problem : model_.whyNot(Action::Start)))
    model_.start();
  ImGui::SameLine();
  if (button("Pause", model_.whyNot(Action::Pause))) model_.pause();
  ImGui::SameLine();
  if (button("Resume", model_.whyNot(Action::Resume))) model_.resume();
  ImGui::SameLine();
  if (confirmedButton("Abort", model_.whyNot(Action::Abort),
                      "Abort the session? It ends now; what was recorded is kept.", "Yes, abort"))
    model_.abort();
  ImGui::SameLine();
  emergencyStopButton(model_);
  // Why the session is not going as planned (a pause, a failed training, a refused grasp), or
  // how it ended: the same words as the operator log and the summary.
  if (const std::string why = model_.reason(); !why.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.55f, 0.3f, 1.0f));
    ImGui::TextWrapped("%s", why.c_str());
    ImGui::PopStyleColor();
  }
  if (!model_.started() && !model_.ended()) runLabels();
  if (const auto robot = model_.robotStatus();
      robot && !robot->stop_reason.empty() && !model_.ended()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.3f, 0.3f, 1));
    ImGui::TextWrapped("robot stopped (%s): the Robot panel's recovery buttons go on from here.",
                       robot->stop_reason.c_str());
    ImGui::PopStyleColor();
  }
  for (const std::string& line : model_.preflight()) {
    const bool bad = line.find("FAILED") != std::string::npos || line.rfind("  ", 0) == 0;
    if (bad && !model_.preflightRunning()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.35f, 0.3f, 1));
      ImGui::TextWrapped("%s", line.c_str());
      ImGui::PopStyleColor();
    } else {
      ImGui::TextWrapped("%s", line.c_str());
    }
  }
  trackingHealth();
  const auto timing = model_.timing();
  heading("cycle");
  ImGui::Text("budget %.1f ms (one EEG block); overruns: %d; late frames: %lld", model_.budgetMs(),
              model_.overruns(), model_.lateFrames());
  if (const std::string clock = model_.eegClockLine(); !clock.empty())
    ImGui::TextUnformatted(clock.c_str());
  if (const std::string fault = model_.eegSourceFault(); !fault.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "EEG source: %s", fault.c_str());
  if (const std::string warning = model_.timingWarning(); !warning.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.2f, 1.0f), "%s", warning.c_str());
  if (ImGui::BeginTable(
          "timing", 6,
          ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const char* h : {"stage", "last ms", "p50", "p90", "p99", "max"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const StageTiming& t : timing) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(t.stage.c_str());
      for (double v : {t.last_ms, t.p50_ms, t.p90_ms, t.p99_ms, t.max_ms}) {
        ImGui::TableNextColumn();
        ImGui::Text("%.2f", v);
      }
    }
    ImGui::EndTable();
  }
  for (const StageTiming& t : timing) {
    if (t.stage == "total") {
      history_.push_back(static_cast<float>(t.last_ms));
      if (history_.size() > 300) history_.erase(history_.begin());
    }
  }
  // The plot's scale, stated: its top is 1.2 blocks, its bottom zero.
  const float top = static_cast<float>(model_.budgetMs() * 1.2);
  char scale[64];
  std::snprintf(scale, sizeof scale, "0 to %.0f ms (budget %.1f)", top, model_.budgetMs());
  ImGui::PlotLines("cycle ms", history_.data(), static_cast<int>(history_.size()), 0, scale, 0.0f,
                   top, ImVec2(0, 60));
  heading("selections");
  for (const std::string& line : model_.selections()) ImGui::TextUnformatted(line.c_str());
}

void SessionPanel::readLabels() {
  const core::RunLabels l = model_.labels();
  std::snprintf(subject_, sizeof subject_, "%s", l.subject.c_str());
  std::snprintf(visit_, sizeof visit_, "%s", l.session.c_str());
  std::snprintf(task_, sizeof task_, "%s", l.task.c_str());
  std::snprintf(run_, sizeof run_, "%s", l.run.c_str());
  labels_read_ = true;
  checkLabels();
}

void SessionPanel::checkLabels() {
  // Once per change, not per frame: the target looks through the BIDS dataset's folders.
  labels_problem_ = model_.labelsProblem();
  labels_target_ = labels_problem_.empty() ? model_.labelsTarget() : "";
}

void SessionPanel::runLabels() {
  heading("subject and run");
  bool changed = false;
  const float width = std::max(60.0f, (ImGui::GetContentRegionAvail().x - 24.0f) / 4.0f);
  struct Field {
    const char* label;
    const char* hint;
    char* text;
    size_t size;
  };
  const Field fields[] = {{"subject", "subject (e.g. 07)", subject_, sizeof subject_},
                          {"session", "session (optional)", visit_, sizeof visit_},
                          {"task", "task", task_, sizeof task_},
                          {"run", "run: next free", run_, sizeof run_}};
  for (size_t i = 0; i < std::size(fields); ++i) {
    if (i > 0) ImGui::SameLine();
    ImGui::SetNextItemWidth(width);
    ImGui::PushID(fields[i].label);
    changed |= ImGui::InputTextWithHint("##label", fields[i].hint, fields[i].text, fields[i].size);
    ImGui::PopID();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%s (BIDS entity: letters and digits)", fields[i].hint);
    recordField(fields[i].label, width);
  }
  if (changed) {
    labels_refused_ = model_.setLabels({subject_, visit_, task_, run_});
    checkLabels();
  }
  if (!labels_refused_.empty()) {
    ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "%s", labels_refused_.c_str());
  } else if (!labels_problem_.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.55f, 0.3f, 1.0f));
    ImGui::TextWrapped("%s", labels_problem_.c_str());
    ImGui::PopStyleColor();
  } else {
    ImGui::TextWrapped("%s", labels_target_.c_str());
  }
}

void SessionPanel::trackingHealth() {
  heading("tracking");
  const double max_age = model_.maxPoseAgeS();
  const ImVec4 lost(1.0f, 0.35f, 0.3f, 1.0f);
  const auto reference = model_.referenceAgeS();
  if (!reference || *reference > max_age) {
    ImGui::TextColored(lost, "reference %d: tracking lost%s", model_.referenceId(),
                       reference ? (" (" + seconds(*reference) + ")").c_str() : " (never seen)");
  } else {
    ImGui::Text("reference %d: seen", model_.referenceId());
  }
  const auto robot = model_.robotStatus();
  const int held = robot ? robot->holding : -1;
  for (const TrackedObject& o : model_.trackedObjects()) {
    ImGui::SameLine(0.0f, 20.0f);
    if (ImGui::GetContentRegionAvail().x < 150.0f) ImGui::NewLine();
    if (o.id == held) {
      ImGui::Text("object %d: in the gripper", o.id);
    } else if (o.age_s > max_age) {
      ImGui::TextColored(lost, "object %d: lost (%s)", o.id, seconds(o.age_s).c_str());
    } else {
      ImGui::Text("object %d: seen", o.id);
    }
  }
}

void HmdPanel::draw() {
  const float width = ImGui::GetContentRegionAvail().x;
  ImageView::drawTexture(texture_, width, width / aspect_, true);
}

}  // namespace arbci::ui

namespace arbci::ui {

void SummaryPanel::draw() {
  if (!model_.ended()) {
    ImGui::TextDisabled("the session is running; its summary appears here when it ends");
    return;
  }
  if (ImGui::BeginTable("summary", 2, ImGuiTableFlags_RowBg)) {
    ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthFixed,
                            ImGui::CalcTextSize("late frames  ").x);
    ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
    for (const auto& [label, value] : model_.endSummary()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextDisabled("%s", label.c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", value.c_str());
    }
    ImGui::EndTable();
  }
}

PanelRegistry::Entry sessionPanel() {
  return {"session",
          "the phase, start/pause/resume/abort, the sequence, the selections, the cycle's timing",
          {[](const PanelContext& c) { return std::make_unique<SessionPanel>(c.model); }}};
}

PanelRegistry::Entry hmdPanel() {
  return {"hmd", "the HMD view as the subject sees it (both eyes)", {[](const PanelContext& c) {
            return std::make_unique<HmdPanel>(c.hmd_texture, c.hmd_aspect);
          }}};
}

PanelRegistry::Entry summaryPanel() {
  return {"summary",
          "the end-of-session summary (opened when the session ends)",
          {[](const PanelContext& c) { return std::make_unique<SummaryPanel>(c.model); }, false}};
}

}  // namespace arbci::ui
