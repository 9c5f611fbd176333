#include "workstation/session_model.h"

#include <cstdio>
#include <fstream>

#include "arbci/session/settings_schema.h"
#include "bids/bids_export.h"
#include "support/session_runs.h"

namespace arbci::app {

std::string timingWarning(const session::Session& session) {
  const session::Presentation& p = session.last().presentation;
  if (!p.display_too_slow || !p.median_frame_ms) return "";
  char text[160];
  std::snprintf(text, sizeof text, "display too slow: a frame every %.1f ms (configured %.1f ms)",
                *p.median_frame_ms, 1000.0 / session.config().paradigm.display_hz);
  return text;
}

std::string trackingAlarm(const session::Session& session) {
  const session::CycleRecord& last = session.last();
  std::vector<int> ids;
  for (const session::WorldObjectSettings& o : session.config().world.objects) {
    if (last.robot.holding() != o.id) ids.push_back(o.id);
  }
  return last.tracking.alarm(ids, last.time_s);
}

std::string statusLine(const session::Session& session) {
  const session::CycleRecord& last = session.last();
  char text[256];
  std::snprintf(text, sizeof text,
                "t=%.1f s  trial %d/%d  %s  cycle p50 %.1f ms  overruns %d  late frames %lld",
                last.time_s, std::max(last.paradigm.trial, 0), session.config().paradigm.trials,
                bci::toString(last.paradigm.phase), session.timing().totalPercentiles().p50,
                session.timing().overruns(), static_cast<long long>(last.presentation.late_frames));
  std::string line = text;
  for (const std::string& warning : {timingWarning(session), trackingAlarm(session)}) {
    if (!warning.empty()) line.append("  [").append(warning).append("]");
  }
  return line;
}

namespace {
BidsEntities entitiesOf(const core::RunLabels& l) {
  return {l.subject, l.session, l.task.empty() ? "arbci" : l.task, l.run};
}
}  // namespace

std::string SessionModel::setLabels(const core::RunLabels& labels) {
  return session_.setLabels(labels);
}

std::string SessionModel::labelsProblem() {
  const core::RunLabels& l = session_.labels();
  if (!bids_root_.empty() && l.subject.empty())
    return "give the subject: the run is exported to the BIDS dataset " + bids_root_.string();
  // Without a BIDS root the subject may stay empty; a label BIDS refuses is refused anyway, so
  // that the folder can be exported later as it is.
  BidsEntities entities = entitiesOf(l);
  if (entities.subject.empty()) entities.subject = "unnamed";
  try {
    checkBidsEntities(entities);
  } catch (const BidsError& error) {
    return error.what();
  }
  return "";
}

void SessionModel::start() {
  // Without a BIDS dataset, a named subject's runs are numbered among the session folders.
  core::RunLabels labels = session_.labels();
  if (bids_root_.empty() && !labels.subject.empty() && labels.run.empty()) {
    labels.run = std::to_string(nextFolderRun(session_.folder(), labels));
    session_.setLabels(labels);
  }
  session_.request(session::StartRequest{});
}

std::string SessionModel::labelsTarget() {
  if (bids_root_.empty()) {
    const core::RunLabels& l = session_.labels();
    const std::string where = "recorded in " + session_.folder().string() +
                              "/summary.json (arbci bids export can file it later)";
    if (l.subject.empty() || !l.run.empty()) return where;
    return "run " + std::to_string(nextFolderRun(session_.folder(), l)) +
           " (the next free among the session folders beside this one), " + where;
  }
  if (!labelsProblem().empty()) return "";
  try {
    return "BIDS: " + (bids_root_ / bidsTarget(bids_root_, entitiesOf(session_.labels()))).string();
  } catch (const BidsError& error) {
    return error.what();
  }
}

const core::Table* SessionModel::settingsSchema() {
  return &session::sessionSchema();
}

std::string SessionModel::checkSettings(const nlohmann::json& settings, const std::string& file) {
  // As `arbci run --session FILE` would read it: the schema's checks, then the files it names.
  try {
    const session::SessionConfig config = session::SessionConfig::parse(settings, file);
    session::checkNamedResources(config);
  } catch (const std::exception& error) {
    return error.what();
  }
  return "";
}

std::string SessionModel::saveSettings(const nlohmann::json& settings, const std::string& file) {
  if (const std::string why = checkSettings(settings, file); !why.empty()) return why;
  std::ofstream out(file);
  out << settings.dump(2) << "\n";
  if (!out) return file + ": cannot write the session file";
  return "saved " + file + " (arbci run --session " + file + ")";
}

void SessionModel::ingest() {
  const session::CycleRecord& last = record();
  if (!scope_ && last.eeg.info) {
    // Ten seconds: the longest time base the EEG panel offers.
    scope_.emplace(*last.eeg.info, 10.0, session_.config().classifier.pipeline.filter);
  }
  if (!scope_) return;
  for (const bci::Block& block : last.eeg.blocks) scope_->append(block);
  for (const session::Presentation::Onset& onset : last.presentation.onsets)
    scope_->markStimulus(onset.sample);
}

void SessionModel::setThreshold(const vision::ThresholdSettings& settings) {
  threshold_ = settings;
  session_.request(session::ThresholdRequest{settings});
}

std::vector<ui::TrackedObject> SessionModel::trackedObjects() {
  std::vector<ui::TrackedObject> out;
  const auto& world = record().tracking.world;
  if (!world) return out;
  for (const vision::ObjectState& o : world->objects()) {
    out.push_back(
        {o.id, o.T_robot_object.translation, o.age(session_.time()), o.reprojection_rms_px});
  }
  return out;
}

std::string SessionModel::worldStatus() {
  const auto& world = record().tracking.world;
  return world ? world->status(session_.time()) : "";
}

int SessionModel::referenceId() {
  const auto& world = record().tracking.world;
  return world ? world->reference().id : session_.config().world.reference_id;
}

cv::Vec3d SessionModel::referencePosition() {
  const auto& world = record().tracking.world;
  return world ? world->reference().T_robot_ref.translation
               : session_.config().world.reference_position;
}

std::optional<double> SessionModel::referenceAgeS() {
  const auto& world = record().tracking.world;
  if (!world) return std::nullopt;
  return world->referenceAge(session_.time());
}

std::optional<bci::P300Model> SessionModel::model() {
  const auto& p300 = record().p300.model;
  if (!p300) return std::nullopt;
  bci::P300Model model = *p300;
  if (const auto& errp = record().errp.model) model.errp = errp;
  return model;
}

void SessionModel::useModel(const bci::P300Model& model) {
  session_.request(session::UseModelRequest{std::make_shared<const bci::P300Model>(model)});
}

std::optional<bci::ErpCurves> SessionModel::sessionErp() {
  const auto& erp = record().p300.erp;
  return erp ? std::optional<bci::ErpCurves>(*erp) : std::nullopt;
}

std::optional<bci::ErpCurves> SessionModel::sessionErrpErp() {
  const auto& erp = record().errp.erp;
  return erp ? std::optional<bci::ErpCurves>(*erp) : std::nullopt;
}

std::vector<std::string> SessionModel::robotLog() {
  const auto& messages = record().robot.messages;
  return messages ? *messages : std::vector<std::string>{};
}

std::string SessionModel::whyNot(Action action) {
  switch (action) {
    case Action::Start:
      return session_.whyNot(session::Action::Start);
    case Action::Pause:
      return session_.whyNot(session::Action::Pause);
    case Action::Resume:
      return session_.whyNot(session::Action::Resume);
    case Action::Abort:
      return session_.whyNot(session::Action::Abort);
    case Action::EmergencyStop:
      return session_.whyNot(session::Action::EmergencyStop);
    case Action::ResetRobot:
      return session_.whyNot(session::Action::ResetRobot);
    case Action::Home:
      return session_.whyNot(session::Action::Home);
    case Action::OpenGripper:
      return session_.whyNot(session::Action::OpenGripper);
    case Action::RetryStep:
      return session_.whyNot(session::Action::RetryStep);
    case Action::SkipTrial:
      return session_.whyNot(session::Action::SkipTrial);
    case Action::EndSession:
      return session_.whyNot(session::Action::EndSession);
  }
  return "";
}

std::string SessionModel::trackingAlarm() {
  return app::trackingAlarm(session_);
}

std::string SessionModel::timingWarning() {
  return app::timingWarning(session_);
}

std::string SessionModel::eegClockLine() {
  const session::EegPart& eeg = record().eeg;
  char text[160];
  std::snprintf(text, sizeof text, "EEG: lost samples %lld, clock drift %+.1f ppm, jitter %.2f ms",
                static_cast<long long>(eeg.lost_samples), eeg.drift_ppm, eeg.jitter_ms);
  return eeg.source_line.empty() ? std::string(text) : std::string(text) + "\n" + eeg.source_line;
}

std::vector<std::string> SessionModel::selections() {
  std::vector<std::string> lines;
  if (const auto& trials = record().paradigm.trials) {
    for (const session::TrialRecord& t : *trials) lines.push_back(session::selectionLine(t));
  }
  return lines;
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
    // null: no object selection was accepted (none made, or every one rejected by the ErrP).
    const nlohmann::json& object = t["selected_object"];
    std::string line = (object.is_number() ? "object " + object.dump() : std::string("no object")) +
                       ": " + outcome;
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
  const nlohmann::json stalls = timing.value("eeg_stalls", nlohmann::json::object());
  rows.emplace_back(
      "EEG stalls",
      stalls.value("count", 0) == 0
          ? std::string("none")
          : std::to_string(stalls.value("count", 0)) + ", longest " +
                number(stalls.value("longest_s", nlohmann::json(0.0)), "%.2f s", 1.0) + ", " +
                std::to_string(stalls.value("uncertain_flashes", 0)) + " flash stamps uncertain");
  rows.emplace_back("folder", session_.folder().string());
  return rows;
}

std::string SessionModel::phase() {
  if (!session_.ended()) return bci::toString(record().paradigm.phase);
  // The summary's words: its "ended" and, where it says more, its "end_reason".
  const std::string& kind = session_.endKind();
  const std::string& why = session_.endReason();
  return "ended: " + kind + (why == kind ? "" : " (" + why + ")");
}

std::string SessionModel::reason() {
  return session_.ended() ? phase() : record().paradigm.status;
}

std::vector<ui::OperatorLine> SessionModel::operatorLog() {
  std::vector<ui::OperatorLine> out;
  for (const session::OperatorMessage& m : session_.operatorLog().messages()) {
    const auto severity = m.severity == session::Severity::Error ? ui::OperatorLine::Severity::Error
                          : m.severity == session::Severity::Warning
                              ? ui::OperatorLine::Severity::Warning
                              : ui::OperatorLine::Severity::Info;
    out.push_back({severity, m.t, m.text});
  }
  return out;
}

std::vector<ui::StageTiming> SessionModel::timing() {
  std::vector<ui::StageTiming> out;
  const auto& last = session_.timing().lastCycle();
  for (const auto& [stage, p] : session_.timing().stagePercentiles()) {
    const auto found = last.find(stage);
    out.push_back({stage, p.p50, p.p90, p.p99, p.max, found == last.end() ? 0.0 : found->second});
  }
  const session::Percentiles total = session_.timing().totalPercentiles();
  out.push_back(
      {"total", total.p50, total.p90, total.p99, total.max, session_.timing().lastTotalMs()});
  return out;
}

}  // namespace arbci::app
