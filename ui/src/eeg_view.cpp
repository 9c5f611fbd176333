// The EEG panel's view: every channel scrolling (scale, time base, the session's filter on or
// off), the photodiode channel and the stimulus onsets marked, and each channel's quality graded
// green / amber / red with the finding and its threshold named.
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "arbci/ui/eeg_view.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

constexpr float kScalesUv[] = {10, 20, 50, 100, 200, 500, 1000, 5000};
constexpr float kTimeBasesS[] = {2, 5, 10};
constexpr float kLabelWidth = 90.0f;
// Trace points a frame, all channels together: what keeps 64 channels within a millisecond.
constexpr int kPointBudget = 48000;

ImU32 gradeColour(bci::Grade grade) {
  switch (grade) {
    case bci::Grade::Bad:
      return IM_COL32(230, 70, 60, 255);
    case bci::Grade::Poor:
      return IM_COL32(240, 170, 40, 255);
    case bci::Grade::Good:
      break;
  }
  return IM_COL32(70, 190, 90, 255);
}

}  // namespace

void EegView::draw(const bci::SignalScope& scope, const session::QualityPart& quality,
                   const bci::QualityThresholds& thresholds, const std::string& photodiode,
                   const std::string& impedance) {
  photodiode_ = photodiode;
  matchQuality(scope, quality);
  drawControls();
  drawQualityLegend(thresholds, impedance);
  drawTraces(scope);
  drawQualityTable(scope);
}

void EegView::setTimeBase(double seconds) {
  time_base_ = 0;
  while (time_base_ + 1 < static_cast<int>(std::size(kTimeBasesS)) &&
         kTimeBasesS[time_base_] < seconds)
    ++time_base_;
}

namespace {

// A choice among `values`, each shown with `format`; `index` the chosen one.
template <size_t N>
void choice(const char* label, const float (&values)[N], const char* format, float width,
            int& index) {
  ImGui::SetNextItemWidth(width);
  char text[32];
  std::snprintf(text, sizeof text, format, values[index]);
  if (!ImGui::BeginCombo(label, text)) return;
  for (int i = 0; i < static_cast<int>(N); ++i) {
    std::snprintf(text, sizeof text, format, values[i]);
    if (ImGui::Selectable(text, i == index)) index = i;
  }
  ImGui::EndCombo();
}

}  // namespace

void EegView::drawControls() {
  choice("scale (per row)", kScalesUv, "+/-%g uV", 110.0f, scale_);
  ImGui::SameLine();
  choice("time base", kTimeBasesS, "%g s", 80.0f, time_base_);
  ImGui::SameLine();
  ImGui::Checkbox("filter", &filtered_);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("the session's online filter (what the classifier sees); off: raw signal");
}

void EegView::matchQuality(const bci::SignalScope& scope, const session::QualityPart& quality) {
  const std::vector<std::string>& channels = scope.info().channels;
  quality_.assign(channels.size(), nullptr);
  for (size_t q = 0; q < quality.quality.size() && q < quality.channels.size(); ++q) {
    const auto at = std::find(channels.begin(), channels.end(), quality.channels[q]);
    if (at != channels.end())
      quality_[static_cast<size_t>(at - channels.begin())] = &quality.quality[q];
  }
}

void EegView::drawQualityLegend(const bci::QualityThresholds& t, const std::string& impedance) {
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped(
      "quality over the last 2 s: green good, amber poor, red bad (flat SD < %g uV, saturated "
      ">= %g uV, line noise > %g/%g uV, drift > %g/%g uV/s, RMS > %g/%g uV); yellow: the "
      "photodiode; blue lines: stimulus onsets",
      t.flat_sd_uv, t.saturated_uv, t.line_poor_uv, t.line_bad_uv, t.drift_poor_uv_s,
      t.drift_bad_uv_s, t.rms_poor_uv, t.rms_bad_uv);
  ImGui::TextWrapped("impedance: %s", impedance.empty()
                                          ? "not reported by this source (LSL streams report "
                                            "it where their metadata has it)"
                                          : impedance.c_str());
  ImGui::PopStyleColor();
}

void EegView::drawTraces(const bci::SignalScope& scope) {
  const bci::SignalInfo& info = scope.info();
  const int channels = info.channelCount();
  const std::string& photodiode = photodiode_;
  const int shown = std::min(scope.capacity(),
                             static_cast<int>(std::lround(kTimeBasesS[time_base_] * info.rate_hz)));
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = std::max(100.0f, ImGui::GetContentRegionAvail().x);
  const float row = std::clamp(
      (ImGui::GetContentRegionAvail().y * 0.6f - 20.0f) / static_cast<float>(std::max(channels, 1)),
      8.0f, 60.0f);
  const float plot_x = origin.x + kLabelWidth, plot_w = width - kLabelWidth;
  const float height = row * static_cast<float>(channels);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->AddRectFilled(ImVec2(plot_x, origin.y), ImVec2(plot_x + plot_w, origin.y + height),
                      IM_COL32(18, 20, 24, 255));
  // Seconds: a tick line each, labelled below.
  const float per_sample = plot_w / static_cast<float>(shown);
  for (int s = 0; s <= static_cast<int>(kTimeBasesS[time_base_]); ++s) {
    const float x = plot_x + plot_w - static_cast<float>(s * info.rate_hz) * per_sample;
    if (x < plot_x - 0.5f) break;
    draw->AddLine(ImVec2(x, origin.y), ImVec2(x, origin.y + height), IM_COL32(60, 64, 72, 255));
    char label[16];
    std::snprintf(label, sizeof label, s == 0 ? "now" : "-%d s", s);
    const float label_w = ImGui::CalcTextSize(label).x;
    draw->AddText(
        ImVec2(std::min(x - label_w / 2, plot_x + plot_w - label_w), origin.y + height + 2.0f),
        IM_COL32(150, 150, 150, 255), label);
  }
  // Stimulus onsets: a line through every channel.
  const std::int64_t end = scope.endSample();
  for (const std::int64_t onset : scope.stimuli()) {
    const std::int64_t ago = end - 1 - onset;
    if (ago < 0 || ago >= shown) continue;
    const float x = plot_x + plot_w - static_cast<float>(ago) * per_sample;
    draw->AddLine(ImVec2(x, origin.y), ImVec2(x, origin.y + height), IM_COL32(90, 120, 200, 110));
  }
  const float scale = kScalesUv[scale_];
  for (int c = 0; c < channels; ++c) {
    const float mid = origin.y + row * (static_cast<float>(c) + 0.5f);
    const bool is_photodiode = info.channels[static_cast<size_t>(c)] == photodiode;
    // The label, in its grade's colour (the photodiode is no EEG: no grade).
    const bci::SignalQuality* q = quality_[static_cast<size_t>(c)];
    const ImU32 label_colour = is_photodiode ? IM_COL32(230, 210, 90, 255)
                               : q           ? gradeColour(q->grade)
                                             : IM_COL32(150, 150, 150, 255);
    draw->AddRectFilled(ImVec2(origin.x, mid - row / 2 + 1),
                        ImVec2(origin.x + 8, mid + row / 2 - 1), label_colour);
    // Rows lower than the text: every k-th channel named (the marks and the table name all).
    const int label_every = static_cast<int>(std::ceil(ImGui::GetFontSize() / row));
    if (c % label_every == 0)
      draw->AddText(ImVec2(origin.x + 12, mid - ImGui::GetFontSize() / 2), label_colour,
                    info.channels[static_cast<size_t>(c)].c_str());
    // The photodiode is scaled to its own range; EEG to the chosen scale, clipped to its row.
    float lo = -scale, hi = scale;
    if (is_photodiode) {
      lo = hi = scope.at(c, 0, false);
      for (int k = 0; k < shown; ++k) {
        const float v = scope.at(c, k, false);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi - lo < 1e-6f) hi = lo + 1.0f;
    }
    const float half = row * 0.48f;
    auto y = [&](float v) {
      const float u = std::clamp((v - lo) / (hi - lo), 0.0f, 1.0f);
      return mid + half - 2.0f * half * u;
    };
    const bool filtered = filtered_ && !is_photodiode;
    const ImU32 colour = is_photodiode ? IM_COL32(230, 210, 90, 255) : IM_COL32(200, 210, 225, 255);
    // A row out of the panel's view costs nothing (many channels in a small panel).
    if (!ImGui::IsRectVisible(ImVec2(plot_x, mid - row / 2),
                              ImVec2(plot_x + plot_w, mid + row / 2)))
      continue;
    scope.copyLast(c, shown, filtered, samples_);
    // At most a point a pixel, and at most kPointBudget points a frame over all channels: the
    // maximum and the minimum of the samples under each column (two pixels wide, wider with
    // many channels). The cost stays bounded whatever the time base and the channel count.
    points_.clear();
    const int columns = std::max(
        16, std::min(static_cast<int>(plot_w / 2.0f), kPointBudget / (2 * std::max(channels, 1))));
    const float column_w = plot_w / static_cast<float>(columns);
    if (shown > 2 * columns) {
      for (int px = 0; px < columns; ++px) {
        const int k0 = static_cast<int>((static_cast<long long>(px) * shown) / columns);
        const int k1 =
            std::max(k0 + 1, static_cast<int>((static_cast<long long>(px + 1) * shown) / columns));
        const auto [lo_it, hi_it] =
            std::minmax_element(samples_.begin() + k0, samples_.begin() + k1);
        const float x = plot_x + column_w * static_cast<float>(px);
        points_.push_back(ImVec2(x, y(*hi_it)));
        points_.push_back(ImVec2(x + column_w / 2.0f, y(*lo_it)));
      }
    } else {
      for (int k = 0; k < shown; ++k) {
        const float x = plot_x + plot_w - static_cast<float>(shown - 1 - k) * per_sample;
        points_.push_back(ImVec2(x, y(samples_[static_cast<size_t>(k)])));
      }
    }
    draw->AddPolyline(points_.data(), static_cast<int>(points_.size()), colour, 0, 1.0f);
  }
  ImGui::Dummy(ImVec2(width, height + ImGui::GetFontSize() + 6.0f));
  // The row under the pointer says its channel's quality.
  if (ImGui::IsItemHovered()) {
    const int c = static_cast<int>((ImGui::GetMousePos().y - origin.y) / row);
    if (c >= 0 && c < channels && quality_[static_cast<size_t>(c)])
      ImGui::SetTooltip("%s: %s", info.channels[static_cast<size_t>(c)].c_str(),
                        quality_[static_cast<size_t>(c)]->finding.c_str());
  }
}

void EegView::drawQualityTable(const bci::SignalScope& scope) {
  if (std::none_of(quality_.begin(), quality_.end(), [](const auto* q) { return q; })) {
    ImGui::TextDisabled("quality: after two seconds of signal");
    return;
  }
  if (!ImGui::BeginTable("quality", 6,
                         ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg |
                             ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollY))
    return;
  ImGui::TableSetupScrollFreeze(0, 1);
  for (const char* h : {"channel", "RMS uV", "50 Hz uV", "60 Hz uV", "drift uV/s", "finding"})
    ImGui::TableSetupColumn(h);
  ImGui::TableHeadersRow();
  const std::string& photodiode = photodiode_;
  const bci::SignalInfo& info = scope.info();
  for (size_t c = 0; c < quality_.size(); ++c) {
    if (info.channels[c] == photodiode || !quality_[c]) continue;
    const bci::SignalQuality& q = *quality_[c];
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(gradeColour(q.grade)), "%s",
                       info.channels[c].c_str());
    for (double v : {q.rms_uv, q.line50_uv, q.line60_uv, q.drift_uv_s}) {
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", v);
    }
    ImGui::TableNextColumn();
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(gradeColour(q.grade)), "%s: %s",
                       bci::toString(q.grade), q.finding.c_str());
  }
  ImGui::EndTable();
}

}  // namespace arbci::ui
