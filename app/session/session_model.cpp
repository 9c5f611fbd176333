#include "session/session_model.h"

#include <cstdio>

namespace arbci::app {

void SessionModel::setThreshold(const vision::ThresholdSettings& settings) {
  threshold_ = settings;
  session_.setThreshold(settings);
}

std::vector<ui::TrackedObject> SessionModel::trackedObjects() {
  std::vector<ui::TrackedObject> out;
  for (const vision::ObjectState& o : session_.vision().world().objects()) {
    out.push_back(
        {o.id, o.T_robot_object.translation, o.age(session_.time()), o.reprojection_rms_px});
  }
  return out;
}

std::string SessionModel::whyNot(Action action) {
  switch (action) {
    case Action::Pause:
      return session_.whyNotPause();
    case Action::Resume:
      return session_.whyNotResume();
    case Action::Home:
      return session_.whyNotHome();
    case Action::OpenGripper:
      return session_.whyNotRelease();
    case Action::RetryStep:
      return session_.whyNotRetry();
    case Action::SkipTrial:
      return session_.whyNotSkip();
  }
  return "";
}

std::vector<std::pair<std::string, std::string>> SessionModel::endSummary() {
  // An ended session's summary no longer changes: built once, not on every frame it is shown.
  if (!end_rows_.empty() || !session_.ended()) return end_rows_;
  end_rows_ = summaryRows();
  return end_rows_;
}

std::vector<std::pair<std::string, std::string>> SessionModel::summaryRows() const {
  const nlohmann::json s = session_.summary();
  std::vector<std::pair<std::string, std::string>> rows;
  auto number = [](const nlohmann::json& v, const char* format, double scale = 1.0) {
    if (!v.is_number()) return std::string("-");
    char text[64];
    std::snprintf(text, sizeof text, format, v.get<double>() * scale);
    return std::string(text);
  };
  const std::string ended = s["ended"].get<std::string>();
  const std::string reason = s["end_reason"].get<std::string>();
  rows.emplace_back("ended", reason == ended ? ended : ended + " (" + reason + ")");
  rows.emplace_back("duration", number(s["duration_s"], "%.1f s"));
  for (const char* kind : {"objects", "cells"}) {
    const nlohmann::json& r = s[kind];
    if (r.is_null()) {
      rows.emplace_back(kind, "no selections");
      continue;
    }
    rows.emplace_back(kind, number(r["accuracy"], "accuracy %.0f %%", 100.0) + ", " +
                                number(r["seconds_per_selection"], "%.1f s per selection") + ", " +
                                number(r["bits_per_minute"], "%.1f bits/min"));
  }
  if (!s["all_inclusive"].is_null())
    rows.emplace_back("all inclusive",
                      number(s["all_inclusive"]["seconds_per_trial"], "%.1f s per trial") + ", " +
                          number(s["all_inclusive"]["bits_per_minute"], "%.1f bits/min"));
  int placed = 0;
  for (const nlohmann::json& t : s["trials"]) {
    const std::string outcome = t["outcome"].get<std::string>();
    const int object = t["selected_object"].get<int>();
    std::string line =
        (object >= 0 ? "object " + std::to_string(object) : std::string("no object")) + ": " +
        outcome;
    if (t["placement_error_m"].is_number()) {
      ++placed;
      line += ", " + number(t["placement_error_m"], "%.1f mm off", 1000.0);
    }
    rows.emplace_back("trial " + std::to_string(t["trial"].get<int>()), line);
  }
  rows.emplace_back("placements", std::to_string(placed) + " of " +
                                      std::to_string(s["trials"].size()) + " trials");
  const nlohmann::json& timing = s["timing"];
  rows.emplace_back("late frames", timing["late_frames"].dump() + ", lost EEG samples " +
                                       timing["lost_samples"].dump());
  rows.emplace_back("folder", session_.folder().string());
  return rows;
}

std::string SessionModel::phase() {
  std::string text = bci::toString(session_.paradigm().phase());
  if (session_.ended() && session_.endReason() != text) text += " (" + session_.endReason() + ")";
  return text;
}

std::vector<ui::StageTiming> SessionModel::timing() {
  std::vector<ui::StageTiming> out;
  const auto& last = session_.timing().lastCycle();
  for (const auto& [stage, p] : session_.timing().stagePercentiles()) {
    const auto found = last.find(stage);
    out.push_back({stage, p.p50, p.p90, p.p99, p.max, found == last.end() ? 0.0 : found->second});
  }
  const Percentiles total = session_.timing().totalPercentiles();
  out.push_back(
      {"total", total.p50, total.p90, total.p99, total.max, session_.timing().lastTotalMs()});
  return out;
}

}  // namespace arbci::app
