// The end-of-session summary: first whether to trust the data (session/trust_report.h: the
// calibration's AUC against chance and the simulated subject, the review, online and post-hoc
// accuracy, timing, channels, the EEG's faults, interruptions, notes), then how it ended,
// accuracy, time per selection, bit rate, placements, late frames, from the summary the ended
// session's last record carries (the window opens it when the session ends).
#include <imgui.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "arbci/session/trust_report.h"
#include "arbci/ui/panel_registry.h"

namespace arbci::ui {
namespace {

using Rows = std::vector<std::pair<std::string, std::string>>;

std::string number(const nlohmann::json& v, const char* format, double scale = 1.0) {
  if (!v.is_number()) return "-";
  char text[64];
  std::snprintf(text, sizeof text, format, v.get<double>() * scale);
  return text;
}

void addRates(const nlohmann::json& s, Rows& rows) {
  for (const char* kind : {"objects", "cells"}) {
    const nlohmann::json& r = s.value(kind, nlohmann::json());
    if (r.is_null()) {
      rows.emplace_back(kind, "no selections");
      continue;
    }
    rows.emplace_back(kind, number(r["accuracy"], "accuracy %.0f %%", 100.0) + ", " +
                                number(r["seconds_per_selection"], "%.1f s per selection") + ", " +
                                number(r["bits_per_minute"], "%.1f bits/min"));
  }
  if (s.contains("all_inclusive") && !s["all_inclusive"].is_null())
    rows.emplace_back("all inclusive",
                      number(s["all_inclusive"]["seconds_per_trial"], "%.1f s per trial") + ", " +
                          number(s["all_inclusive"]["bits_per_minute"], "%.1f bits/min"));
}

// "cell 1,1 (intended 3,1: wrong)", or "cell 3,1" when it was the intended one.
std::string choice(const char* what, const nlohmann::json& selected, const nlohmann::json& intended,
                   bool& wrong) {
  auto text = [](const nlohmann::json& v) {
    if (v.is_array() && v.size() == 2) return v[0].dump() + "," + v[1].dump();
    return v.dump();
  };
  // null: no selection was accepted (none made, or every one rejected by the ErrP).
  if (selected.is_null()) return std::string("no ") + what;
  std::string out = std::string(what) + " " + text(selected);
  if (!intended.is_null() && selected != intended) {
    wrong = true;
    out += " (intended " + text(intended) + ": wrong)";
  }
  return out;
}

void addTrials(const nlohmann::json& s, Rows& rows) {
  int placed = 0, placed_right = 0;
  const nlohmann::json trials = s.value("trials", nlohmann::json::array());
  for (const nlohmann::json& t : trials) {
    bool wrong = false;
    std::string line = choice("object", t.value("selected_object", nlohmann::json()),
                              t.value("intended_object", nlohmann::json()), wrong) +
                       ", " +
                       choice("cell", t.value("selected_cell", nlohmann::json()),
                              t.value("intended_cell", nlohmann::json()), wrong) +
                       ": " + t.value("outcome", "");
    if (t.contains("placement_error_m") && t["placement_error_m"].is_number()) {
      ++placed;
      placed_right += wrong ? 0 : 1;
      line += ", " + number(t["placement_error_m"], "%.1f mm off", 1000.0);
    }
    const nlohmann::json interruptions = t.value("interruptions", nlohmann::json::array());
    if (!interruptions.empty())
      line += "; interrupted " + std::to_string(interruptions.size()) + " time" +
              (interruptions.size() == 1 ? "" : "s") + " (" + interruptions[0].value("kind", "") +
              (interruptions.size() > 1 ? ", ..." : "") + ")";
    rows.emplace_back("trial " + std::to_string(t.value("trial", 0)), line);
  }
  rows.emplace_back("placements", std::to_string(placed) + " of " + std::to_string(trials.size()) +
                                      " trials, " + std::to_string(placed_right) +
                                      " where intended");
}

void addTiming(const nlohmann::json& s, Rows& rows) {
  const nlohmann::json timing = s.value("timing", nlohmann::json::object());
  rows.emplace_back("late frames", timing.value("late_frames", nlohmann::json(0)).dump() +
                                       ", lost EEG samples " +
                                       timing.value("lost_samples", nlohmann::json(0)).dump());
  const nlohmann::json stalls = timing.value("eeg_stalls", nlohmann::json::object());
  rows.emplace_back("EEG stalls",
                    stalls.value("count", 0) == 0
                        ? std::string("none")
                        : std::to_string(stalls.value("count", 0)) + ", longest " +
                              number(stalls.value("longest_s", nlohmann::json(0.0)), "%.2f s") +
                              ", " + std::to_string(stalls.value("uncertain_flashes", 0)) +
                              " flash stamps uncertain");
}

// The summary's figures as label/value rows.
Rows summaryRows(const nlohmann::json& s) {
  Rows rows;
  const std::string ended = s.value("ended", "");
  const std::string reason = s.value("end_reason", "");
  rows.emplace_back("ended", reason == ended ? ended : ended + " (" + reason + ")");
  rows.emplace_back("duration", number(s.value("duration_s", nlohmann::json()), "%.1f s"));
  addRates(s, rows);
  addTrials(s, rows);
  addTiming(s, rows);
  rows.emplace_back("folder", s.value("folder", ""));
  return rows;
}

class SummaryPanel final : public Panel {
 public:
  const char* title() const override { return "Session summary"; }
  void draw(const PanelInput& in) override {
    if (!in.record.ended || !in.record.summary) {
      ImGui::TextDisabled("the session is running; its summary appears here when it ends");
      return;
    }
    // An ended session's summary no longer changes: its rows are made once.
    if (shown_ != in.record.summary) {
      shown_ = in.record.summary;
      rows_ = summaryRows(*shown_);
      trust_ = session::trustRows(*shown_);
    }
    // Whether to trust the data first: what a new experimenter must look at again is marked.
    int cautions = 0;
    for (const session::TrustRow& row : trust_) cautions += row.caution;
    ImGui::TextColored(
        cautions ? ImVec4(1.0f, 0.7f, 0.3f, 1.0f) : ImVec4(0.5f, 0.9f, 0.5f, 1.0f), "%s",
        cautions ? (std::to_string(cautions) +
                    " reason(s) to look again before using this run's data (marked !)")
                       .c_str()
                 : "nothing in this run's record calls for caution");
    if (ImGui::BeginTable("trust", 2, ImGuiTableFlags_RowBg)) {
      ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthFixed,
                              ImGui::CalcTextSize("post hoc objects  ").x);
      ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
      for (const session::TrustRow& row : trust_) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        if (row.caution)
          ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.25f, 1.0f), "! %s", row.what.c_str());
        else
          ImGui::TextDisabled("%s", row.what.c_str());
        ImGui::TableNextColumn();
        ImGui::TextWrapped("%s", row.text.c_str());
      }
      ImGui::EndTable();
    }
    ImGui::Separator();
    if (!ImGui::BeginTable("summary", 2, ImGuiTableFlags_RowBg)) return;
    ImGui::TableSetupColumn("what", ImGuiTableColumnFlags_WidthFixed,
                            ImGui::CalcTextSize("late frames  ").x);
    ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
    for (const auto& [label, value] : rows_) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextDisabled("%s", label.c_str());
      ImGui::TableNextColumn();
      ImGui::TextWrapped("%s", value.c_str());
    }
    ImGui::EndTable();
  }

 private:
  std::shared_ptr<const nlohmann::json> shown_;
  Rows rows_;
  std::vector<session::TrustRow> trust_;
};

}  // namespace

PanelRegistry::Entry summaryPanel() {
  return {"summary", "the end-of-session summary (opened when the session ends)",
          PanelParts([] { return std::make_unique<SummaryPanel>(); }, false)};
}

}  // namespace arbci::ui
