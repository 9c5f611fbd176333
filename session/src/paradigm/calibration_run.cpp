#include "arbci/session/paradigm/calibration_run.h"

#include <cstdio>

namespace arbci::session {

void CalibrationRun::retaken(int selection, int object, const std::string& reason, Cycle& cycle,
                             const StageServices& s) {
  Retake r{selection, object, reason.empty() ? "interrupted" : reason, selection + 1};
  s.log.write("calibration_retake", cycle.time_s,
              {{"selection", r.selection},
               {"object", r.object},
               {"reason", r.reason},
               {"retaken_as", r.retaken_as}});
  cycle.annotate(cycle.eeg_sample, "Calibration selection " + std::to_string(r.selection) +
                                       " interrupted (" + r.reason + "): left out of training, " +
                                       "retaken as selection " + std::to_string(r.retaken_as));
  s.tell.say(cycle.time_s, Severity::Info,
             "calibration selection " + std::to_string(r.selection) + " (object " +
                 std::to_string(r.object) + ") interrupted (" + r.reason +
                 "): cued again as selection " + std::to_string(r.retaken_as) +
                 "; training leaves the interrupted flashes out");
  retakes_.push_back(r);
}

void CalibrationRun::trainingStarted(const Cycle& cycle, const StageServices& s) {
  awaiting_p300_ = true;
  awaiting_errp_ = errp_;
  errp_report_.reset();
  errp_failure_.clear();
  since_ = cycle.time_s;
  frames_ = 0;
  longest_s_ = 0.0;
  last_at_.reset();
  if (cycle.record.presentation.shown) last_at_ = cycle.record.presentation.at_s;
  s.log.write("training_started", cycle.time_s, {{"method", method_}});
}

void CalibrationRun::frameShown(const Presentation& shown) {
  if (!shown.shown || !awaiting_p300_) return;
  if (last_at_) {
    ++frames_;
    longest_s_ = std::max(longest_s_, shown.at_s - *last_at_);
  }
  last_at_ = shown.at_s;
}

CalibrationRun::Outcome CalibrationRun::collect(const Cycle& cycle, const StageServices& s) {
  if (!awaiting()) return Outcome::Waiting;
  const P300Part& p300 = cycle.record.p300;
  const ErrpPart& errp = cycle.record.errp;
  if (awaiting_p300_ && !p300.training_error.empty()) {
    awaiting_p300_ = awaiting_errp_ = false;
    error_ = p300.training_error;
    s.log.write("training_failed", cycle.time_s, {{"reason", error_}});
    s.tell.say(cycle.time_s, Severity::Error, "training failed: " + error_);
    return Outcome::Failed;
  }
  if (awaiting_p300_ && p300.trained) {
    awaiting_p300_ = false;
    report_ = p300.trained;
    trained_on_ = p300.trained_on;
  }
  if (awaiting_errp_ && errp.trained) {
    awaiting_errp_ = false;
    errp_report_ = errp.trained;
  }
  if (awaiting_errp_ && !errp.training_error.empty()) {
    awaiting_errp_ = false;
    errp_failure_ = errp.training_error;
  }
  if (awaiting()) return Outcome::Waiting;
  saveModel(cycle);
  s.log.write("trained", cycle.time_s,
              {{"method", method_},
               {"training_s", cycle.time_s - since_},
               {"frames_while_training", frames_},
               {"longest_frame_ms", 1000.0 * longest_s_},
               {"median_frame_ms", cycle.record.presentation.median_frame_ms.value_or(0.0)},
               {"auc", report_->auc},
               {"accuracy_by_sequences", report_->accuracy},
               {"selections_used", trained_on_},
               {"selections_left_out", p300.left_out}});
  tellTrained(cycle, s);
  if (errp_) logErrp(cycle, s);
  return Outcome::Trained;
}

void CalibrationRun::saveModel(const Cycle& cycle) {
  // Both classifiers trained: one model file, the ErrP classifier inside the P300 one's.
  bci::P300Model model = *cycle.record.p300.model;
  if (errp_report_ && cycle.record.errp.model) {
    model.errp = cycle.record.errp.model;
    model.errp_auc = errp_report_->auc;
  }
  model.save(model_file_);
}

void CalibrationRun::tellTrained(const Cycle& cycle, const StageServices& s) const {
  const bci::EvaluationReport& r = *report_;
  char text[200];
  std::snprintf(text, sizeof text,
                "classifier trained (%s): cross-validated AUC %.3f [%.3f, %.3f], accuracy "
                "%.0f %% after %zu sequences",
                method_.c_str(), r.auc, r.auc_interval.low, r.auc_interval.high,
                r.accuracy.empty() ? 0.0 : 100.0 * r.accuracy.back(), r.accuracy.size());
  s.tell.say(cycle.time_s, Severity::Info, text);
  if (retakes_.empty()) return;
  std::string cut;
  for (const Retake& retake : retakes_)
    cut += (cut.empty() ? "" : ", ") + std::to_string(retake.selection) + " (" + retake.reason +
           ", retaken as " + std::to_string(retake.retaken_as) + ")";
  s.tell.say(cycle.time_s, Severity::Info,
             "trained on " + std::to_string(trained_on_.size()) +
                 " whole calibration selections; left out, interrupted: " + cut);
}

void CalibrationRun::logErrp(const Cycle& cycle, const StageServices& s) const {
  if (errp_report_) {
    s.log.write("errp_trained", cycle.time_s,
                {{"auc", errp_report_->auc},
                 {"auc_95", {errp_report_->auc_interval.low, errp_report_->auc_interval.high}},
                 {"error_feedbacks", errp_report_->target_flashes},
                 {"correct_feedbacks", errp_report_->other_flashes}});
    return;
  }
  s.log.write("errp_training_failed", cycle.time_s, {{"reason", errp_failure_}});
  s.tell.say(
      cycle.time_s, Severity::Warning,
      "no ErrP classifier (" + errp_failure_ + "): selections are executed without an ErrP check");
}

void CalibrationRun::reviewed(const std::string& decision, double auc, double time_s) {
  reviews_.push_back({{"decision", decision}, {"auc", auc}, {"at_s", time_s}});
}

void CalibrationRun::restart() {
  report_.reset();
  errp_report_.reset();
  trained_on_.clear();
  error_.clear();
  errp_failure_.clear();
  awaiting_p300_ = awaiting_errp_ = false;
}

void CalibrationRun::summarise(nlohmann::json& summary) const {
  if (!reviews_.empty()) summary["calibration"]["reviews"] = reviews_;
  if (report_) {
    summary["calibration"].update(
        {{"selections", report_->selections.size()},
         {"selections_used", trained_on_},
         {"auc", report_->auc},
         {"auc_95", {report_->auc_interval.low, report_->auc_interval.high}},
         {"flashes", {{"targets", report_->target_flashes}, {"others", report_->other_flashes}}},
         {"accuracy_by_sequences", report_->accuracy}});
  }
  if (retakes_.empty()) return;
  nlohmann::json& retaken = summary["calibration"]["retaken"];
  for (const Retake& r : retakes_) {
    retaken.push_back({{"selection", r.selection},
                       {"object", r.object},
                       {"reason", r.reason},
                       {"retaken_as", r.retaken_as}});
  }
}

}  // namespace arbci::session
