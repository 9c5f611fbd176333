#include "erp_plots.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace arbci::ui {
namespace {

const ImU32 kTarget = IM_COL32(220, 50, 50, 255), kOther = IM_COL32(40, 110, 200, 255),
            kTargetBand = IM_COL32(220, 50, 50, 60), kOtherBand = IM_COL32(40, 110, 200, 60),
            kDifference = IM_COL32(235, 235, 235, 255), kAxis = IM_COL32(150, 150, 150, 255),
            kWindow = IM_COL32(250, 240, 200, 40);

ImU32 diverging(double v) {
  v = std::clamp(v, -1.0, 1.0);
  const int fade = static_cast<int>(255.0 * (1.0 - std::abs(v)));
  return v < 0.0 ? IM_COL32(fade, fade, 255, 255) : IM_COL32(255, fade, fade, 255);
}

}  // namespace

void drawErpPlots(const bci::ErpCurves& erp, const char* target, const char* other) {
  const int channels = static_cast<int>(erp.channels.size()), samples = erp.samples();
  if (channels == 0 || samples < 2) return;
  const Eigen::MatrixXd difference = erp.difference();
  const Eigen::MatrixXd band_t = 1.96 * erp.target_se, band_o = 1.96 * erp.other_se;
  const double limit = erp.scaleUv();
  ImGui::TextColored(ImVec4(0.86f, 0.2f, 0.2f, 1.0f), "%s (%d)", target, erp.targets);
  ImGui::SameLine();
  ImGui::TextColored(ImVec4(0.16f, 0.43f, 0.78f, 1.0f), "%s (%d)", other, erp.others);
  ImGui::SameLine();
  ImGui::TextWrapped("difference (white); 95 %% bands; %s; reference %s", erp.filterText().c_str(),
                     erp.referenceText().c_str());
  const float width = std::max(120.0f, (ImGui::GetContentRegionAvail().x - 8.0f) / 2.0f);
  const float height = 70.0f, ticks = ImGui::GetFontSize() + 2.0f;  // the ms labels under it
  ImDrawList* draw = ImGui::GetWindowDrawList();
  for (int c = 0; c < channels; ++c) {
    if (c % 2 == 1) ImGui::SameLine();
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    ImGui::InvisibleButton(("erp" + std::to_string(c)).c_str(), ImVec2(width, height + ticks));
    auto at = [&](int s, double uv) {
      return ImVec2(origin.x + width * s / (samples - 1),
                    origin.y + height * static_cast<float>(0.5 - 0.5 * uv / limit));
    };
    auto atTime = [&](double t_s, double uv) {
      return at(static_cast<int>(std::lround((t_s - erp.start_s) * erp.rate_hz)), uv);
    };
    draw->AddRectFilled(atTime(erp.window_start_s, limit),
                        atTime(std::min(erp.window_end_s, erp.timeS(samples - 1)), -limit),
                        kWindow);
    draw->AddRect(origin, ImVec2(origin.x + width, origin.y + height), kAxis);
    draw->AddLine(at(0, 0.0), at(samples - 1, 0.0), kAxis);
    draw->AddLine(atTime(0.0, limit), atTime(0.0, -limit), kAxis);
    for (int s = 0; s + 1 < samples; ++s) {
      draw->AddQuadFilled(at(s, erp.other_mean(c, s) + band_o(c, s)),
                          at(s + 1, erp.other_mean(c, s + 1) + band_o(c, s + 1)),
                          at(s + 1, erp.other_mean(c, s + 1) - band_o(c, s + 1)),
                          at(s, erp.other_mean(c, s) - band_o(c, s)), kOtherBand);
      draw->AddQuadFilled(at(s, erp.target_mean(c, s) + band_t(c, s)),
                          at(s + 1, erp.target_mean(c, s + 1) + band_t(c, s + 1)),
                          at(s + 1, erp.target_mean(c, s + 1) - band_t(c, s + 1)),
                          at(s, erp.target_mean(c, s) - band_t(c, s)), kTargetBand);
    }
    for (int s = 0; s + 1 < samples; ++s) {
      draw->AddLine(at(s, erp.other_mean(c, s)), at(s + 1, erp.other_mean(c, s + 1)), kOther, 1.5f);
      draw->AddLine(at(s, erp.target_mean(c, s)), at(s + 1, erp.target_mean(c, s + 1)), kTarget,
                    1.5f);
      draw->AddLine(at(s, difference(c, s)), at(s + 1, difference(c, s + 1)), kDifference, 1.0f);
    }
    draw->AddText(ImVec2(origin.x + 4, origin.y + 2), kDifference,
                  erp.channels[static_cast<size_t>(c)].c_str());
    // The scale: microvolts at the top and bottom edges, milliseconds every 100 (labelled every
    // 200) under the axis.
    char label[24];
    std::snprintf(label, sizeof label, "+%.0f uV", limit);
    draw->AddText(ImVec2(origin.x + width - ImGui::CalcTextSize(label).x - 3, origin.y + 1), kAxis,
                  label);
    std::snprintf(label, sizeof label, "-%.0f uV", limit);
    draw->AddText(ImVec2(origin.x + width - ImGui::CalcTextSize(label).x - 3,
                         origin.y + height - ImGui::GetFontSize() - 1),
                  kAxis, label);
    const int first_ms = static_cast<int>(std::ceil(erp.timeS(0) * 10.0)) * 100;
    for (int ms = first_ms; ms <= erp.timeS(samples - 1) * 1000.0 + 1e-6; ms += 100) {
      const ImVec2 bottom = atTime(ms / 1000.0, -limit);
      draw->AddLine(bottom, ImVec2(bottom.x, bottom.y - 4.0f), kAxis);
      if (ms % 200 != 0) continue;
      std::snprintf(label, sizeof label, "%d", ms);
      const float w = ImGui::CalcTextSize(label).x;
      draw->AddText(
          ImVec2(std::clamp(bottom.x - w / 2, origin.x, origin.x + width - w), bottom.y + 1), kAxis,
          label);
    }
  }
  ImGui::TextDisabled("ms after the stimulus");
}

void drawSignedR2(const bci::ErpCurves& erp) {
  const int channels = static_cast<int>(erp.channels.size()), samples = erp.samples();
  if (channels == 0 || samples < 2) return;
  const double limit = std::max(1e-6, erp.signed_r2.cwiseAbs().maxCoeff());
  ImGui::TextWrapped(
      "signed r^2 per channel (rows) and time: red target > non-target, blue below; "
      "|r^2| up to %.3f",
      limit);
  const float labels = 48.0f;
  const float width = ImGui::GetContentRegionAvail().x - 8.0f - labels;
  const float row = std::clamp(160.0f / channels, 3.0f, 16.0f);
  const ImVec2 corner = ImGui::GetCursorScreenPos();
  const ImVec2 origin(corner.x + labels, corner.y);
  ImGui::InvisibleButton("r2", ImVec2(width + labels, row * channels));
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const int every = std::max(1, static_cast<int>(std::ceil(14.0f / row)));
  for (int c = 0; c < channels; c += every) {
    draw->AddText(ImVec2(corner.x, origin.y + row * c), kDifference,
                  erp.channels[static_cast<size_t>(c)].c_str());
  }
  for (int c = 0; c < channels; ++c) {
    for (int s = 0; s < samples; ++s) {
      const float x0 = origin.x + width * s / samples, x1 = origin.x + width * (s + 1) / samples;
      draw->AddRectFilled(ImVec2(x0, origin.y + row * c),
                          ImVec2(x1 + 0.5f, origin.y + row * (c + 1)),
                          diverging(erp.signed_r2(c, s) / limit));
    }
  }
  const float zero = origin.x + width * static_cast<float>(-erp.start_s * erp.rate_hz) / samples;
  draw->AddLine(ImVec2(zero, origin.y), ImVec2(zero, origin.y + row * channels),
                IM_COL32(0, 0, 0, 255));  // the stimulus
}

void drawScalpMap(const bci::ErpCurves& erp) {
  const std::optional<bci::ScalpMap> map = bci::scalpMapAt(erp, bci::ScalpTime{});
  if (!map) {
    ImGui::TextDisabled("no scalp map: fewer than 3 channels have 10-20 names");
    return;
  }
  const bci::ScalpTime when;
  ImGui::TextWrapped(
      "target - non-target at %.0f ms (the difference's peak in %.0f-%.0f ms), +/-%.1f uV",
      map->time_s * 1000.0, when.from_s * 1000.0, when.to_s * 1000.0, map->limit_uv);
  const float size = 180.0f, head = 0.55f;
  const ImVec2 corner = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("scalp", ImVec2(size, size));
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 centre(corner.x + size / 2, corner.y + size / 2);
  constexpr int kCells = 45;
  const float cell = size / kCells;
  for (int i = 0; i < kCells; ++i) {
    for (int j = 0; j < kCells; ++j) {
      const double px = ((i + 0.5) / kCells * 2.0 - 1.0) * head;
      const double py = (1.0 - (j + 0.5) / kCells * 2.0) * head;
      if (px * px + py * py > head * head) continue;
      const ImVec2 a(corner.x + i * cell, corner.y + j * cell);
      draw->AddRectFilled(a, ImVec2(a.x + cell + 0.5f, a.y + cell + 0.5f),
                          diverging(map->at(px, py) / map->limit_uv));
    }
  }
  draw->AddCircle(centre, size / 2, kAxis, 64);
  for (const bci::ScalpMap::Electrode& e : map->electrodes) {
    const ImVec2 p(centre.x + static_cast<float>(e.x / head) * size / 2,
                   centre.y - static_cast<float>(e.y / head) * size / 2);
    draw->AddCircleFilled(p, 2.5f, IM_COL32(0, 0, 0, 255));
    draw->AddText(ImVec2(p.x + 4, p.y - 12), IM_COL32(0, 0, 0, 255), e.name.c_str());
  }
}

}  // namespace arbci::ui
