#include <imgui.h>

#include "arbci/ui/panels.h"
#include "widgets.h"

namespace arbci::ui {

void SessionPanel::draw() {
  ImGui::Text("%s", model_.phase().c_str());
  ImGui::Text("trial %d of %d, sequence %d, session time %.1f s", model_.trial(), model_.trials(),
              model_.sequence(), model_.sessionTime());
  if (!model_.started()) {
    if (ImGui::Button("Start")) model_.start();
  } else {
    if (ImGui::Button("Pause")) model_.pause();
    ImGui::SameLine();
    if (ImGui::Button("Resume")) model_.resume();
    ImGui::SameLine();
    if (ImGui::Button("Abort")) model_.abort();
  }
  ImGui::SameLine();
  emergencyStopButton(model_);
  if (const auto robot = model_.robotStatus(); robot && !robot->stop_reason.empty()) {
    ImGui::TextColored(ImVec4(1, 0.3f, 0.3f, 1),
                       "robot fault: %s. Robot panel: Reset, then Home; then Resume.",
                       robot->stop_reason.c_str());
  }
  const auto timing = model_.timing();
  heading("cycle");
  ImGui::Text("budget %.1f ms (one EEG block); overruns: %d; late frames: %lld", model_.budgetMs(),
              model_.overruns(), model_.lateFrames());
  if (const std::string clock = model_.eegClockLine(); !clock.empty())
    ImGui::TextUnformatted(clock.c_str());
  if (const std::string warning = model_.timingWarning(); !warning.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.2f, 1.0f), "%s", warning.c_str());
  if (ImGui::BeginTable("timing", 6, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
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
  ImGui::PlotLines("cycle ms", history_.data(), static_cast<int>(history_.size()), 0, nullptr, 0.0f,
                   static_cast<float>(model_.budgetMs() * 1.2), ImVec2(0, 60));
  heading("selections");
  for (const std::string& line : model_.selections()) ImGui::TextUnformatted(line.c_str());
}

void HmdPanel::draw() {
  const float width = ImGui::GetContentRegionAvail().x;
  ImageView::drawTexture(texture_, width, width / aspect_, true);
}

}  // namespace arbci::ui
