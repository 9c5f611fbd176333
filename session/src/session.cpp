#include "arbci/session/session.h"

#include <fstream>

#include "arbci/core/whole_file.h"
#include "arbci/session/stages/robot_stage.h"
#include "arbci/session/trigger_output.h"
#include "stage_assembly.h"

namespace arbci::session {
Session::Session(SessionConfig config, const SessionOptions& requested,
                 const DisplayFactory& display)
    : config_(configFor(std::move(config), requested)),
      options_(optionsFor(requested, config_)),
      clock_(options_.clock, config_.paradigm.display_hz),
      folder_(options_.folder),
      operator_log_(options_.progress),
      timing_(1000.0 * config_.eeg.block_size / config_.eeg.rate_hz) {
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (error)
    throw std::runtime_error(folder_.string() + ": cannot create the session folder (" +
                             error.message() + ")");
  log_ = std::make_unique<SessionLog>(folder_ / "log.jsonl");
  const StageServices services{clock_, *log_, operator_log_};
  AssembledStages assembled = assembleStages(config_, options_, clock_, folder_, services, display);
  stages_ = std::move(assembled.stages);
  robot_ = assembled.robot;
  trigger_ = std::move(assembled.trigger);
  std::ofstream(folder_ / "session.json") << nlohmann::json{
      {"source", config_.source},
      {"seed", config_.eeg.seed},
      {"trials", config_.paradigm.trials}}.dump(2);
  log_->write(
      "session_started", 0.0,
      {{"folder", folder_.string()}, {"session", config_.source}, {"seed", config_.eeg.seed}});
  clock_.start();
  records_[current_].host_s = clock_.hostOf(0.0);
  records_[current_].labels = options_.labels;
  // Nobody will press Start: the pre-flight check runs from the first frame.
  if (!options_.experimenter) queued_.push_back(StartRequest{});
}

Session::~Session() {
  try {
    if (!ended_) endRun("closed");
  } catch (const std::exception&) {
    // Nothing more can be saved from a destructor.
  }
}

bool Session::request(Request request) {
  if (const auto* labels = std::get_if<LabelsRequest>(&request)) {
    const std::string why = setLabels(labels->labels);
    if (why.empty()) return true;
    operator_log_.add(time(), Severity::Warning, "subject and run not changed: " + why);
    return false;
  }
  if (std::holds_alternative<ApplySettingsRequest>(request)) {
    // The window opens a session again with them; a session cannot change its own.
    operator_log_.add(time(), Severity::Warning,
                      "settings not applied: only the window's start screen applies settings to "
                      "a run (this one keeps its own)");
    return false;
  }
  const std::optional<Action> action = actionOf(request);
  if (action) {
    const std::string why = whyNot(*action);
    if (!why.empty()) {
      log_->write("refused", time(), {{"action", toString(*action)}, {"why", why}});
      operator_log_.add(time(), Severity::Warning,
                        std::string(toString(*action)) + " refused: " + why);
      return false;
    }
    if (*action == Action::Resume || *action == Action::RetryStep || *action == Action::SkipTrial)
      fault_since_ = -1.0;
  }
  if (std::holds_alternative<EmergencyStopRequest>(request)) {
    log_->write("emergency_stop", time(), {{"by", "experimenter"}});
    operator_log_.add(time(), Severity::Error, "EMERGENCY STOP by the experimenter");
    robot_->stopNow(time());  // not a frame later
  }
  queued_.push_back(std::move(request));
  return true;
}

void Session::beginCycle() {
  const int last = current_;
  current_ = 1 - current_;
  CycleRecord& record = records_[current_];
  record = CycleRecord{};
  record.requests = std::move(records_[last].posted);
  records_[last].posted.clear();
  for (Request& r : queued_) record.requests.push_back(std::move(r));
  queued_.clear();
  record.frame = frame_;
  record.labels = options_.labels;
  record.time_s = clock_.frameTime(frame_);
  record.host_s = clock_.hostOf(record.time_s);
  // When this frame will be on screen: stepped, now; in a window, a period after the last one
  // (or now, when the cycle itself is late).
  record.due_s = record.time_s;
  if (!clock_.stepped() && records_[last].presented) {
    const double last_shown = clock_.sessionOf(records_[last].presented->host_s);
    record.due_s = std::max(record.time_s, last_shown + clock_.framePeriodS());
  }
}

bool Session::step() {
  if (ended_) return false;
  beginCycle();
  CycleRecord& record = records_[current_];
  Cycle cycle{record.frame, record.time_s, record.due_s,          record.host_s, 0,
              clock_,       record,        records_[1 - current_]};
  timing_.beginCycle();
  for (const auto& stage : stages_) {
    stage->step(cycle);
    timing_.mark(stage->name());
  }
  record.eeg_sample = cycle.eeg_sample;
  if (options_.presents_itself) presented(clock_.presentedNow(record.time_s));
  timing_.mark("present");
  recordCycleTime();
  endIfDone();
  ++frame_;
  clock_.pace(frame_);
  return !ended_;
}

void Session::presented(double host_s, const std::optional<RuntimeFrame>& runtime) {
  CycleRecord& record = records_[current_];
  if (ended_ || record.presented) return;
  record.presented = CycleRecord::Presented{host_s, clock_.sampleAt(host_s)};
  if (runtime) {
    // The stamp the flashes take (the predicted display time) beside the handover, which is what
    // a window's swap stamp would have been.
    nlohmann::json fields = {{"frame", record.frame},
                             {"display_s", clock_.sessionOf(host_s)},
                             {"submitted_s", clock_.sessionOf(runtime->submitted_host_s)},
                             {"lead_ms", 1000.0 * (host_s - runtime->submitted_host_s)}};
    if (runtime->head) fields["head"] = *runtime->head;
    log_->write("hmd_frame", clock_.sessionOf(host_s), fields);
  }
  if (trigger_) writeTriggers(record, host_s);
}

void Session::writeTriggers(const CycleRecord& record, double host_s) {
  const auto& feedback = record.paradigm.feedback;
  const double after = clock_.stepped() ? 0.0 : std::max(0.0, bci::hostSeconds() - host_s);
  trigger_->presented(record.frame, host_s, after, record.paradigm.first_shown,
                      feedback ? &*feedback : nullptr);
  for (const TriggerWrite& w : trigger_->take()) {
    const double latency_ms = 1000.0 * (w.written_host_s - w.swap_host_s);
    trigger_writes_ += 1;
    trigger_latency_max_ms_ = std::max(trigger_latency_max_ms_, latency_ms);
    log_->write("trigger", clock_.sessionOf(w.swap_host_s),
                {{"frame", w.frame},
                 {"byte", w.byte},
                 {"what", w.what},
                 {"swap_s", clock_.sessionOf(w.swap_host_s)},
                 {"written_s", clock_.sessionOf(w.written_host_s)},
                 {"latency_ms", latency_ms}});
  }
  if (trigger_->failedWrites() > trigger_failures_told_) {
    // Told once: the flashes go on, and the recording keeps their onsets.
    if (trigger_failures_told_ == 0)
      operator_log_.say(record.time_s, Severity::Warning,
                        trigger_->fault() + " (" + std::to_string(trigger_->failedWrites()) +
                            " trigger(s) not sent; the recording keeps every onset)");
    log_->write("trigger_failed", record.time_s,
                {{"text", trigger_->fault()}, {"failed", trigger_->failedWrites()}});
    trigger_failures_told_ = trigger_->failedWrites();
  }
}

void Session::recordCycleTime() {
  CycleRecord& record = records_[current_];
  const double total = timing_.endCycle();
  record.stage_ms = timing_.lastCycle();
  record.compute_ms = total;
  record.overruns = timing_.overruns();
  const nlohmann::json fields = {
      {"frame", record.frame}, {"compute_ms", total}, {"stages", timing_.lastCycle()}};
  if (total > timing_.budgetMs()) log_->write("overrun", record.time_s, fields);
  if (record.frame % 6 == 0) log_->write("cycle", record.time_s, fields);
  tellLogNews(record.time_s);
}

void Session::tellLogNews(double time_s) {
  if (const std::string news = log_->news(); !news.empty())
    operator_log_.add(time_s, log_->failing() ? Severity::Error : Severity::Warning, news);
}

void Session::endIfDone() {
  const CycleRecord& record = records_[current_];
  const double time = record.time_s;
  if (!record.end_reason.empty()) {
    endRun(record.end_reason, record.end_kind);
    return;
  }
  // Without an experimenter, a fault or a stop ends the run after a while.
  const bci::Phase phase = record.paradigm.phase;
  if (phase == bci::Phase::RobotFault || phase == bci::Phase::EmergencyStop) {
    if (fault_since_ < 0.0) fault_since_ = time;
    if (!options_.experimenter && time - fault_since_ > options_.fault_wait_s)
      endRun(std::string("stopped waiting for the experimenter after: ") + bci::toString(phase));
  } else {
    fault_since_ = -1.0;
  }
  // The last placement is measured before the run ends (a status after the drop, or 3 s).
  if (phase == bci::Phase::Finished && !record.robot.measuring) endRun("finished");
  if (phase == bci::Phase::Aborted) {
    // The whole reason (who or what aborted it), not the word alone.
    std::string reason = "aborted";
    const std::string said = std::string(bci::toString(bci::Phase::Aborted)) + ": ";
    for (const PhaseChange& change : record.paradigm.phase_changes) {
      if (change.phase != bci::Phase::Aborted || change.text.empty()) continue;
      // "aborted: by the experimenter" is the kind and the reason: the reason alone.
      reason = change.text.rfind(said, 0) == 0 ? change.text.substr(said.size()) : change.text;
    }
    endRun(reason, "aborted");
  }
  if (options_.flashes_only_s > 0.0 && time >= options_.flashes_only_s) endRun("timing check done");
  if (!options_.experimenter && time > options_.max_session_s)
    endRun("the session ran past its time limit");
}

void Session::endRun(const std::string& reason, const std::string& kind) {
  if (ended_) return;
  ended_ = true;
  end_reason_ = reason;
  end_kind_ = kind.empty() ? endKindOf(reason, last().paradigm.phase) : kind;
  // A closing cycle at the last one's time: the last frame's stamps, the last samples, the end.
  const CycleRecord& last_record = records_[current_];
  CycleRecord closing;
  closing.frame = last_record.frame;
  closing.time_s = last_record.time_s;
  closing.host_s = last_record.host_s;
  closing.due_s = last_record.due_s;
  closing.eeg_sample = last_record.eeg_sample;
  Cycle cycle{closing.frame,      closing.time_s, closing.due_s, closing.host_s,
              closing.eeg_sample, clock_,         closing,       last_record};
  for (const auto& stage : stages_) stage->stop(cycle, reason);
  log_->write("session_ended", last_record.time_s, {{"reason", reason}});
  tellLogNews(last_record.time_s);
  // The terminal prints the end itself (after its status line); the window lists it here.
  operator_log_.add(
      last_record.time_s, end_kind_ == "finished" ? Severity::Info : Severity::Error,
      "session ended: " + end_kind_ + (reason == end_kind_ ? "" : " (" + reason + ")"));
  const auto summary_json = std::make_shared<const nlohmann::json>(summary());
  // Whole or not at all: on a full disk a cut summary would read as a broken run.
  if (const std::string why =
          core::writeWholeFile(folder_ / "summary.json", summary_json->dump(2) + "\n");
      !why.empty()) {
    log_->write("summary_not_written", last_record.time_s, {{"text", why}});
    operator_log_.add(last_record.time_s, Severity::Error, "summary.json not written: " + why);
  }
  // The last record says how the run ended, for whoever reads it from now on.
  CycleRecord& ended = records_[current_];
  ended.ended = true;
  ended.end_reason = reason;
  ended.end_kind = end_kind_;
  ended.summary = summary_json;
}

std::string Session::setLabels(const core::RunLabels& labels) {
  if (ended_) return "the session has ended";
  if (last().paradigm.phase != bci::Phase::Setup)
    return "the session has started: its subject and run are fixed";
  options_.labels = labels;
  records_[current_].labels = labels;
  return "";
}

nlohmann::json Session::summary() const {
  const core::RunLabels& l = options_.labels;
  nlohmann::json out = {
      {"labels",
       {{"subject", l.subject},
        {"session", l.session},
        {"task", l.task},
        {"run", l.run},
        {"age", l.age},
        {"sex", l.sex},
        {"handedness", l.handedness}}},
      {"session", config_.source},
      {"folder", folder_.string()},
      {"seed", config_.eeg.seed},
      {"ended", end_kind_},
      {"end_reason", end_reason_},
      {"duration_s", last().time_s},
      {"frames", frame_},
      {"cycle", timing_.toJson()},
      {"overruns", timing_.overruns()},
  };
  if (log_->lost() > 0) out["log_lines_lost"] = log_->lost();
  if (trigger_)
    out["trigger"] = {{"device", trigger_->device()},
                      {"written", trigger_writes_},
                      {"failed", trigger_->failedWrites()},
                      {"latency_max_ms", trigger_latency_max_ms_}};
  for (const auto& stage : stages_) stage->report(out);
  return out;
}

nlohmann::json Session::run(const std::function<bool()>& interrupted) {
  while (step()) {
    if (interrupted && interrupted()) request(AbortRequest{});  // ends at the next frame
  }
  return summary();
}

}  // namespace arbci::session
