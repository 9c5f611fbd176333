#include <imgui.h>

#include <cfloat>
#include <cstdio>
#include <string>

#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"

namespace arbci::ui {
namespace {

// A control with its label above it, across the panel: no label is cut in a narrow panel.
bool slider(const char* label, int* value, int low, int high) {
  ImGui::TextUnformatted(label);
  ImGui::SetNextItemWidth(-FLT_MIN);
  return ImGui::SliderInt((std::string("##") + label).c_str(), value, low, high);
}

}  // namespace

void ThresholdPanel::draw() {
  vision::ThresholdSettings s = model_.threshold();
  const char* modes[] = {"constant", "automatic (median of marker pixels)",
                         "automatic (midrange, ARToolKitPlus)", "adaptive (local)"};
  int mode = static_cast<int>(s.mode);
  ImGui::TextUnformatted("threshold mode");
  ImGui::SetNextItemWidth(-FLT_MIN);
  bool changed = ImGui::Combo("##mode", &mode, modes, 4);
  s.mode = static_cast<vision::ThresholdMode>(mode);
  if (s.mode != vision::ThresholdMode::Adaptive) {
    changed |= slider("value", &s.value, 1, 254);
    bool vignetting = s.vignetting.has_value();
    if (ImGui::Checkbox("vignetting compensation", &vignetting)) {
      s.vignetting = vignetting
                         ? std::optional<vision::Vignetting>(vision::Vignetting{-20, -10, -10})
                         : std::nullopt;
      changed = true;
    }
    if (s.vignetting) {
      changed |= slider("corners", &s.vignetting->corners, -80, 80);
      changed |= slider("left/right", &s.vignetting->left_right, -80, 80);
      changed |= slider("top/bottom", &s.vignetting->top_bottom, -80, 80);
    }
  } else {
    changed |= slider("least contrast (0: from the image noise)", &s.min_contrast, 0, 80);
  }
  if (changed) model_.setThreshold(s);
  const vision::DetectionResult d = model_.detection();
  ImGui::TextWrapped("threshold used: %d (%s), %d candidates, %d attempt(s)", d.threshold,
                     d.threshold_mode.c_str(), d.candidates, d.threshold_attempts);
  const float width = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) / 2.0f;
  camera_.draw(model_.cameraImage(), width);
  ImGui::SameLine();
  binary_.draw(model_.binaryImage(), width);
  ImGui::TextWrapped("%s", model_.worldStatus().c_str());
  // Short headers (the panel may be narrow); the tooltip over the table says what they are.
  if (ImGui::BeginTable(
          "markers", 5,
          ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("id", 0, 0.5f);
    ImGui::TableSetupColumn("conf.", 0, 0.6f);
    ImGui::TableSetupColumn("bits", 0, 0.5f);
    ImGui::TableSetupColumn("x y z mm", 0, 1.6f);
    ImGui::TableSetupColumn("age, rms", 0, 1.3f);
    ImGui::TableHeadersRow();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "id: marker id; conf.: ID confidence; bits: bits the BCH code corrected;\n"
          "x y z: robot-frame position (mm); age: since last seen; rms: reprojection (px)");
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
        ImGui::Text("%.0f %.0f %.0f", found->position[0] * 1000, found->position[1] * 1000,
                    found->position[2] * 1000);
        ImGui::TableNextColumn();
        ImGui::Text("%.2f s, %.2f px", found->age_s, found->reprojection_px);
      } else {
        ImGui::TextDisabled(m.id == model_.referenceId() ? "reference" : "-");
        ImGui::TableNextColumn();
      }
    }
    ImGui::EndTable();
  }
}

PanelRegistry::Entry thresholdPanel() {
  return {"threshold",
          "the tracker's threshold, the binary image and the markers found",
          {[](const PanelContext& c) { return std::make_unique<ThresholdPanel>(c.model); }}};
}

}  // namespace arbci::ui
