#include "evaluation_plots.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace arbci::ui {
namespace {

const ImU32 kAxis = IM_COL32(150, 150, 150, 255), kLine = IM_COL32(120, 190, 255, 255),
            kChance = IM_COL32(200, 120, 60, 255), kBand = IM_COL32(120, 190, 255, 50);

struct Reference {
  double value;
  const char* label;
};

// A step that gives about four ticks over `span` (1, 2 or 5 times a power of ten).
double tickStep(double span) {
  const double raw = span / 4.0, power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= m * power) return m * power;
  }
  return 10.0 * power;
}

// Values by sequences (1, 2, ...) on axes with ticks: y from 0 to `top` in `unit`, x the sequence
// count; `low`/`high` a band (intervals) when given; reference lines labelled.
void drawBySequences(const char* id, const std::vector<double>& values, double top,
                     const char* unit, double scale, const std::vector<Reference>& references,
                     const std::vector<double>& low = {}, const std::vector<double>& high = {}) {
  const int n = static_cast<int>(values.size());
  if (n == 0) return;
  const float left = ImGui::CalcTextSize("100 %").x + 6.0f, below = ImGui::GetFontSize() + 4.0f;
  const float width = std::max(160.0f, ImGui::GetContentRegionAvail().x - left - 8.0f);
  const float height = 70.0f;
  const ImVec2 corner = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, ImVec2(width + left, height + below));
  const ImVec2 origin(corner.x + left, corner.y);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  auto at = [&](double k, double v) {  // k: 0-based sequence index
    const float x = origin.x + (n == 1 ? width / 2 : width * static_cast<float>(k) / (n - 1));
    const float y =
        origin.y + height * static_cast<float>(1.0 - std::clamp(v * scale / top, 0.0, 1.0));
    return ImVec2(x, y);
  };
  draw->AddRect(origin, ImVec2(origin.x + width, origin.y + height), kAxis);
  char text[32];
  const double step = tickStep(top);
  for (double v = 0.0; v <= top + 1e-9; v += step) {
    const ImVec2 p = at(0, v / scale);
    draw->AddLine(ImVec2(origin.x - 4, p.y), ImVec2(origin.x, p.y), kAxis);
    std::snprintf(text, sizeof text, "%g%s", v, unit);
    draw->AddText(ImVec2(corner.x, p.y - ImGui::GetFontSize() / 2), kAxis, text);
  }
  const int every = std::max(1, static_cast<int>(std::ceil(n * 24.0f / width)));
  for (int k = 0; k < n; k += every) {
    const ImVec2 p = at(k, 0.0);
    draw->AddLine(p, ImVec2(p.x, p.y + 4), kAxis);
    std::snprintf(text, sizeof text, "%d", k + 1);
    draw->AddText(ImVec2(p.x - ImGui::CalcTextSize(text).x / 2, p.y + 3), kAxis, text);
  }
  for (const Reference& r : references) {
    const ImVec2 a = at(0, r.value), b = at(n - 1, r.value);
    draw->AddLine(ImVec2(origin.x, a.y), ImVec2(origin.x + width, b.y), kChance);
    draw->AddText(ImVec2(origin.x + 4, a.y - ImGui::GetFontSize()), kChance, r.label);
  }
  if (static_cast<int>(low.size()) == n && static_cast<int>(high.size()) == n) {
    for (int k = 0; k + 1 < n; ++k)
      draw->AddQuadFilled(
          at(k, high[static_cast<size_t>(k)]), at(k + 1, high[static_cast<size_t>(k + 1)]),
          at(k + 1, low[static_cast<size_t>(k + 1)]), at(k, low[static_cast<size_t>(k)]), kBand);
  }
  for (int k = 0; k + 1 < n; ++k)
    draw->AddLine(at(k, values[static_cast<size_t>(k)]),
                  at(k + 1, values[static_cast<size_t>(k + 1)]), kLine, 1.5f);
  for (int k = 0; k < n; ++k)
    draw->AddCircleFilled(at(k, values[static_cast<size_t>(k)]), 2.5f, kLine);
}

}  // namespace

void drawEvaluation(const bci::EvaluationReport& cv) {
  ImGui::TextWrapped("AUC %.3f (95 %% interval %.3f-%.3f) over %d target and %d other flashes",
                     cv.auc, cv.auc_interval.low, cv.auc_interval.high, cv.target_flashes,
                     cv.other_flashes);
  if (!cv.selection_metrics) {
    ImGui::TextWrapped("no selection metrics: the stimulus codes are classes, not choices");
    return;
  }
  ImGui::TextWrapped("%d selections; chance %.0f %%, beaten at p < 0.05 from %.0f %%",
                     cv.selections_with_truth, 100.0 * cv.chance, 100.0 * cv.chance_95);
  // Accuracy and bit rate side by side: the ERPs below stay in view.
  if (!ImGui::BeginTable("by sequences", 2, ImGuiTableFlags_SizingStretchSame)) return;
  ImGui::TableNextColumn();
  if (!cv.accuracy.empty()) {
    ImGui::TextWrapped("accuracy by sequences: %.0f %% after %zu (95 %% bands)",
                       100.0 * cv.accuracy.back(), cv.accuracy.size());
    std::vector<double> low, high;
    for (const bci::Interval& i : cv.accuracy_interval) {
      low.push_back(i.low);
      high.push_back(i.high);
    }
    drawBySequences("##accuracy", cv.accuracy, 100.0, " %", 100.0,
                    {{cv.chance, "chance"}, {cv.chance_95, "p < 0.05"}}, low, high);
  }
  ImGui::TableNextColumn();
  if (!cv.bits_per_minute.empty()) {
    const double best = *std::max_element(cv.bits_per_minute.begin(), cv.bits_per_minute.end());
    const double top = std::max(1.0, tickStep(best) * std::ceil(best / tickStep(best) + 1e-9));
    ImGui::TextWrapped("bits/min by sequences (the flashes only): best %.1f", best);
    drawBySequences("##bits", cv.bits_per_minute, top, "", 1.0, {});
  }
  ImGui::EndTable();
  ImGui::TextDisabled("x: sequences");
}

}  // namespace arbci::ui
