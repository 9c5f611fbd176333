// The Threshold panel: the tracker's threshold mode and value, the live binarised image beside
// the camera image, and the markers found with ID, confidence and pose.
#include <imgui.h>

#include <cfloat>
#include <cstdio>
#include <string>

#include "arbci/ui/image_view.h"
#include "arbci/ui/panel_registry.h"

namespace arbci::ui {
namespace {

// A control with its label above it, across the panel: no label is cut in a narrow panel.
bool slider(const char* label, int* value, int low, int high) {
  ImGui::TextUnformatted(label);
  ImGui::SetNextItemWidth(-FLT_MIN);
  return ImGui::SliderInt((std::string("##") + label).c_str(), value, low, high);
}

class ThresholdPanel final : public Panel {
 public:
  const char* title() const override { return "Threshold"; }
  void draw(const PanelInput& in) override;

 private:
  void markerTable(const PanelInput& in);
  ImageView camera_, binary_;
};

void ThresholdPanel::draw(const PanelInput& in) {
  const session::TrackingPart& tracking = in.record.tracking;
  vision::ThresholdSettings s = tracking.threshold;
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
  if (changed) in.requests.post(session::ThresholdRequest{s});
  const vision::DetectionResult& d = tracking.detection;
  ImGui::TextWrapped("threshold used: %d (%s), %d candidates, %d attempt(s)", d.threshold,
                     d.threshold_mode.c_str(), d.candidates, d.threshold_attempts);
  const float width = (ImGui::GetContentRegionAvail().x - ImGui::GetStyle().ItemSpacing.x) / 2.0f;
  camera_.draw(tracking.left_image, width);
  ImGui::SameLine();
  binary_.draw(tracking.binary, width);
  if (tracking.world) ImGui::TextWrapped("%s", tracking.world->status(in.record.time_s).c_str());
  markerTable(in);
}

void ThresholdPanel::markerTable(const PanelInput& in) {
  const session::TrackingPart& tracking = in.record.tracking;
  const double now = in.record.time_s;
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
    for (const vision::MarkerDetection& m : tracking.detection.markers) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%d", m.id);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", m.confidence);
      ImGui::TableNextColumn();
      ImGui::Text("%d", m.corrected_bits);
      ImGui::TableNextColumn();
      const auto found = tracking.world ? tracking.world->object(m.id) : std::nullopt;
      if (found) {
        const cv::Vec3d p = found->T_robot_object.translation;
        ImGui::Text("%.0f %.0f %.0f", p[0] * 1000, p[1] * 1000, p[2] * 1000);
        ImGui::TableNextColumn();
        ImGui::Text("%.2f s, %.2f px", found->age(now), found->reprojection_rms_px);
      } else {
        const bool reference = tracking.world && m.id == tracking.world->reference().id;
        ImGui::TextDisabled(reference ? "reference" : "-");
        ImGui::TableNextColumn();
      }
    }
    ImGui::EndTable();
  }
}

}  // namespace

PanelRegistry::Entry thresholdPanel() {
  PanelParts parts{[] { return std::make_unique<ThresholdPanel>(); }};
  parts.shots.push_back({"threshold", "after half a second of the simulated cameras",
                         [](const session::CycleRecord& r) { return r.frame >= 30; }});
  return {"threshold", "the tracker's threshold, the binary image and the markers found",
          std::move(parts)};
}

}  // namespace arbci::ui
