#include <imgui.h>

#include <cstdio>

#include "arbci/ui/panels.h"

namespace arbci::ui {

void ThresholdPanel::draw() {
  vision::ThresholdSettings s = model_.threshold();
  const char* modes[] = {"constant", "automatic (median of marker pixels)",
                         "automatic (midrange, ARToolKitPlus)", "adaptive (local)"};
  int mode = static_cast<int>(s.mode);
  bool changed = ImGui::Combo("mode", &mode, modes, 4);
  s.mode = static_cast<vision::ThresholdMode>(mode);
  if (s.mode != vision::ThresholdMode::Adaptive) {
    changed |= ImGui::SliderInt("value", &s.value, 1, 254);
    bool vignetting = s.vignetting.has_value();
    if (ImGui::Checkbox("vignetting compensation", &vignetting)) {
      s.vignetting = vignetting
                         ? std::optional<vision::Vignetting>(vision::Vignetting{-20, -10, -10})
                         : std::nullopt;
      changed = true;
    }
    if (s.vignetting) {
      changed |= ImGui::SliderInt("corners", &s.vignetting->corners, -80, 80);
      changed |= ImGui::SliderInt("left/right", &s.vignetting->left_right, -80, 80);
      changed |= ImGui::SliderInt("top/bottom", &s.vignetting->top_bottom, -80, 80);
    }
  } else {
    changed |= ImGui::SliderInt("least contrast (0: from noise)", &s.min_contrast, 0, 80);
  }
  if (changed) model_.setThreshold(s);
  const vision::DetectionResult d = model_.detection();
  ImGui::Text("threshold used: %d (%s), %d candidates, %d attempt(s)", d.threshold,
              d.threshold_mode.c_str(), d.candidates, d.threshold_attempts);
  const float width = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) / 2.0f;
  camera_.draw(model_.cameraImage(), width);
  ImGui::SameLine();
  binary_.draw(model_.binaryImage(), width);
  ImGui::TextUnformatted(model_.worldStatus().c_str());
  if (ImGui::BeginTable("markers", 5, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
    ImGui::TableSetupColumn("id");
    ImGui::TableSetupColumn("confidence");
    ImGui::TableSetupColumn("corrected bits");
    ImGui::TableSetupColumn("robot-frame position (mm)");
    ImGui::TableSetupColumn("age / reprojection");
    ImGui::TableHeadersRow();
    const auto objects = model_.trackedObjects();
    for (const vision::MarkerDetection& m : d.markers) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%d", m.id);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", m.confidence);
      ImGui::TableNextColumn();
      ImGui::Text("%d", m.corrected_bits);
      ImGui::TableNextColumn();
      const TrackedObject* found = nullptr;
      for (const TrackedObject& o : objects) {
        if (o.id == m.id) found = &o;
      }
      if (found) {
        ImGui::Text("%.1f %.1f %.1f", found->position[0] * 1000, found->position[1] * 1000,
                    found->position[2] * 1000);
        ImGui::TableNextColumn();
        ImGui::Text("%.2f s / %.2f px", found->age_s, found->reprojection_px);
      } else {
        ImGui::TextDisabled(m.id == model_.referenceId() ? "reference" : "-");
        ImGui::TableNextColumn();
      }
    }
    ImGui::EndTable();
  }
}

}  // namespace arbci::ui
