#include "arbci/session/stages/paradigm_stage.h"

#include <cmath>
#include <cstdio>

#include "arbci/session/experimenter.h"

namespace arbci::session {

std::string stimulusCodeMap(const WorldSettings& world, const std::vector<size_t>& slots) {
  std::string map;
  auto add = [&map](int code, const std::string& what) {
    if (!map.empty()) map.push_back(';');
    map.append(std::to_string(code)).append("=").append(what);
  };
  for (size_t k = 0; k < slots.size(); ++k)
    add(static_cast<int>(k) + 1, "object " + std::to_string(world.objects[slots[k]].id));
  for (int row = 1; row <= world.grid.rows; ++row) add(100 + row, "row " + std::to_string(row));
  for (int column = 1; column <= world.grid.columns; ++column)
    add(100 + world.grid.rows + column, "column " + std::to_string(column));
  return map;
}

std::vector<size_t> allSlots(const WorldSettings& world) {
  std::vector<size_t> slots(world.objects.size());
  for (size_t i = 0; i < slots.size(); ++i) slots[i] = i;
  return slots;
}

ParadigmStage::ParadigmStage(const ParadigmStageSettings& settings, const StageServices& services)
    : settings_(settings),
      s_(services),
      paradigm_(settings_.paradigm, static_cast<int>(settings_.world.objects.size()),
                settings_.world.grid.rows, settings_.world.grid.columns, settings_.seed),
      slots_(allSlots(settings_.world)),
      trials_(settings_.intended),
      errp_(settings_.errp_threshold),
      calibration_(settings_.classifier_method, settings_.model_file, settings_.paradigm.errp),
      view_watch_(settings_.world, settings_.paradigm.no_view_pause_s, settings_.experimenter,
                  settings_.max_retakes) {
  nameObjects();
  // Learning from use: every object selection waits for the fit with it in (judgeHeldSelection).
  if (settings_.learns) {
    paradigm_.holdArm(true, kArmHeld);
    paradigm_.holdUncertainCells(true);
    paradigm_.setObjectSequences(bci::Paradigm::ObjectSequences::Learning);
  }
}

void ParadigmStage::nameObjects() {
  std::vector<int> ids;
  for (size_t slot : slots_) ids.push_back(settings_.world.objects[slot].id);
  paradigm_.setObjectNames(ids);
}

void ParadigmStage::step(Cycle& cycle) {
  cycle.record.paradigm = ParadigmPart{};
  // A new feedback's score is awaited; a score that came is the feedback's.
  if (cycle.record.presentation.feedback) errp_.awaitScore();
  if (cycle.record.errp.score) errp_.scored(cycle.record.errp.score->second);
  calibration_.frameShown(cycle.record.presentation);
  for (const Request& request : cycle.record.requests) act(request, cycle);
  takeRobotNotes(cycle);
  watchGrasp(cycle);
  collectTraining(cycle);
  followLearning(cycle);
  const Presentation& shown = cycle.record.presentation;
  if (shown.shown) paradigm_.presented(shown.frame, shown.at_s);
  stimulus_ = paradigm_.frame(cycle.frame, cycle.due_s);
  view_watch_.withholdStale(cycle, slots_, paradigm_.phase(), stimulus_);
  handleEvents(cycle);
  decideIfReady(cycle);
  judgeFeedback(cycle);
  eeg_watch_.watch(cycle, paradigm_, reasons_, s_);
  view_watch_.watch(cycle, paradigm_, slots_.size(), reasons_, s_);
  publish(cycle);
}

void ParadigmStage::publish(Cycle& cycle) {
  ParadigmPart& part = cycle.record.paradigm;
  part.phase = paradigm_.phase();
  part.interrupted = paradigm_.interrupted();
  part.trial = paradigm_.trial();
  part.sequence = paradigm_.sequence();
  if (paradigm_.calibrating())
    part.calibration_selection = {
        std::min(paradigm_.calibrationDone() + 1, settings_.paradigm.calibration_selections),
        settings_.paradigm.calibration_selections};
  part.calibration_retakes = paradigm_.calibrationRetakes();
  part.reflashed_sequences = paradigm_.reflashedSequences();
  part.errp_awaited = paradigm_.awaitingErrpVerdict();
  part.stimulus = stimulus_;
  part.slots = slots_;
  const TrialRecord* trial = trials_.find(paradigm_.trial());
  if (trial && trial->selected_object > 0) part.selected_object = trial->selected_object;
  part.trials = std::make_shared<const std::vector<TrialRecord>>(trials_.trials());
  part.calibration = calibration_.report();
  part.review = review_;
  if (part.phase == bci::Phase::Paused) part.waiting_for = view_watch_.waitingFor();
  part.status = reasons_.status;
}

void ParadigmStage::act(const Request& request, Cycle& cycle) {
  const double time = cycle.time_s;
  if (std::holds_alternative<BeginRequest>(request)) {
    if (paradigm_.phase() != bci::Phase::Setup) return;
    chooseSelectableObjects(cycle);
    paradigm_.start(!cycle.record.p300.model && !settings_.learns);
    if (settings_.learns) trials_.nextStartsAt(cycle.time_s);
  } else if (const auto* pause = std::get_if<PauseRequest>(&request)) {
    reasons_.stopped_because = pause->reason.empty() ? "paused by the experimenter" : pause->reason;
    if (!pause->reason.empty()) {
      reasons_.status = "paused: " + pause->reason;
      s_.log.write("paused", time, {{"reason", pause->reason}});
    }
    paradigm_.pause();
  } else if (std::holds_alternative<ResumeRequest>(request)) {
    if (paradigm_.interrupted()) cycle.post(RobotResetIfLatchedRequest{time});
    reasons_.status.clear();
    // Only a selection that lacks a withheld flash is retaken; any other goes on.
    paradigm_.resume(view_watch_.retakeOnResume());
  } else if (std::holds_alternative<AbortRequest>(request)) {
    paradigm_.abort();
  } else if (std::holds_alternative<EmergencyStopRequest>(request)) {
    // The session sent the arm its STOP already; the paradigm stops where it is.
    reasons_.stopped_because = "emergency stop";
    paradigm_.emergencyStop();
  } else if (std::holds_alternative<RetryStepRequest>(request)) {
    s_.log.write("recovery", time, {{"action", "retry step"}, {"trial", paradigm_.trial()}});
    cycle.post(RobotResetIfLatchedRequest{time});
    reasons_.status.clear();
    retrying_ = true;
    paradigm_.retryStep();
    handleEvents(cycle);  // the robot's command goes out with this cycle's requests
    retrying_ = false;
  } else if (std::holds_alternative<SkipTrialRequest>(request)) {
    s_.log.write("recovery", time, {{"action", "skip trial"}, {"trial", paradigm_.trial()}});
    cycle.post(RobotResetIfLatchedRequest{time});
    reasons_.status.clear();
    paradigm_.skipTrial();
    handleEvents(cycle);
  } else if (std::holds_alternative<GoOnlineRequest>(request)) {
    answerReview(true, cycle);
  } else if (std::holds_alternative<RecalibrateRequest>(request)) {
    answerReview(false, cycle);
  } else if (std::holds_alternative<EndSessionRequest>(request)) {
    const bci::Phase phase = paradigm_.phase();
    s_.log.write("recovery", time, {{"action", "end session"}});
    paradigm_.abort();
    cycle.end(std::string("ended by the experimenter in: ") + bci::toString(phase),
              endKindOf("", phase));
  }
}

void ParadigmStage::takeRobotNotes(Cycle& cycle) {
  using Kind = RobotPart::Note::Kind;
  for (const RobotPart::Note& note : cycle.record.robot.notes) {
    switch (note.kind) {
      case Kind::Outcome:
        trials_.at(paradigm_.trial()).outcome = note.text;
        break;
      case Kind::Placement:
        trials_.at(note.trial).placement_error_m = note.error_m;
        break;
      case Kind::Finished:
        // A step that did not go says why on the panel until the experimenter acts.
        if (!note.success && paradigm_.phase() != bci::Phase::RobotFault)
          reasons_.status = note.text;
        paradigm_.robotFinished(note.success, note.text);
        if (!note.success && !settings_.experimenter) recoverUnattended(note.text, cycle);
        break;
      case Kind::PutDownEnded:
        // Home after a put-down, the table seen again: the next trial offers what is in view.
        chooseSelectableObjects(cycle);
        paradigm_.robotFinished(true, "");
        break;
    }
  }
}

// Nobody to ask after a robot step that failed (a grasp that closed on nothing, a path the arm
// could not follow): the arm goes home and the run goes on with the next trial, the trial's
// outcome saying what happened. An arm that still holds the object cannot go on: the run waits
// as for a fault (and ends after robot fault_wait_s, saying so).
void ParadigmStage::recoverUnattended(const std::string& why, Cycle& cycle) {
  if (paradigm_.phase() != bci::Phase::RobotFault || cycle.record.robot.holding()) return;
  const double time = cycle.time_s;
  const int trial = paradigm_.trial();
  const std::string outcome = "failed: " + why + "; the arm went home and the run went on";
  s_.log.write(
      "recovery", time,
      {{"action", "home and the next trial (unattended)"}, {"trial", trial}, {"why", why}});
  s_.tell.say(time, Severity::Warning, "trial " + std::to_string(trial) + ": " + outcome);
  cycle.post(RobotResetIfLatchedRequest{time});
  cycle.post(RobotHomeRequest{time});
  reasons_.status.clear();
  paradigm_.skipTrial(outcome);
  handleEvents(cycle);
}

void ParadigmStage::watchGrasp(Cycle& cycle) {
  grasp_view_.observe(cycle.time_s, cycle.record.robot, cycle.record.tracking);
  const auto sight = grasp_view_.take();
  if (!sight) return;
  s_.log.write("grasp_view", cycle.time_s,
               {{"object", sight->object},
                {"seconds", sight->seconds},
                {"pose_age_max_s", sight->max_age_s},
                {"never_seen", sight->never_seen}});
  TrialRecord& trial = trials_.at(paradigm_.trial());
  if (trial.robot_object == sight->object)
    trial.grasp_pose_age_max_s = sight->never_seen ? -1.0 : sight->max_age_s;
}

void ParadigmStage::collectTraining(Cycle& cycle) {
  switch (calibration_.collect(cycle, s_)) {
    case CalibrationRun::Outcome::Waiting:
      return;
    case CalibrationRun::Outcome::Failed:
      reasons_.status = "training failed: " + calibration_.error();
      paradigm_.modelTrained(false, calibration_.error());
      return;
    case CalibrationRun::Outcome::Trained:
      reviewCalibration(cycle);
      return;
  }
}

void ParadigmStage::reviewCalibration(Cycle& cycle) {
  const double auc = calibration_.report() ? calibration_.report()->auc : 0.0;
  const double minimum = settings_.min_auc;
  // A NaN AUC (one class missing) is below any minimum.
  const bool below = minimum > 0.0 && !(auc >= minimum);
  char text[200];
  std::snprintf(text, sizeof text, "calibration AUC %.3f%s", auc,
                below ? " below gates.min_auc" : "");
  std::string words = text;
  if (below) {
    std::snprintf(text, sizeof text, " %.3f", minimum);
    words += text;
  }
  if (below && !settings_.experimenter) {
    // Nobody to decide: the run does not go online on a calibration below the lab's minimum.
    const std::string reason = words + ": not going online unattended";
    s_.log.write("calibration_review", cycle.time_s,
                 {{"auc", auc}, {"min_auc", minimum}, {"decision", "end: nobody to ask"}});
    calibration_.reviewed("ended unattended", auc, cycle.time_s);
    cycle.end(reason, "aborted");
    paradigm_.abort();
    return;
  }
  if (!below && !(settings_.review && settings_.experimenter)) {
    goOnline(cycle);
    return;
  }
  review_ = ParadigmPart::Review{auc, minimum, below, calibration_round_};
  if (const auto& r = calibration_.report()) {
    review_->auc_low = r->auc_interval.low;
    review_->auc_high = r->auc_interval.high;
    review_->targets = r->target_flashes;
    review_->others = r->other_flashes;
  }
  reasons_.status = "calibration review: " + words +
                    "; Go online or Recalibrate (Classifier training panel: ERP, AUC, accuracy)";
  s_.log.write("calibration_review", cycle.time_s,
               {{"auc", auc}, {"min_auc", minimum}, {"below", below}, {"decision", "asked"}});
  s_.tell.say(cycle.time_s, below ? Severity::Warning : Severity::Info, reasons_.status);
}

void ParadigmStage::goOnline(Cycle& cycle) {
  review_.reset();
  chooseSelectableObjects(cycle);
  trials_.nextStartsAt(cycle.time_s);  // the first trial's time counts from here
  paradigm_.modelTrained(true, "");
}

void ParadigmStage::answerReview(bool go_online, Cycle& cycle) {
  if (!review_) return;
  const double auc = review_->auc;
  const char* decision = go_online ? "go online" : "recalibrate";
  s_.log.write("calibration_review", cycle.time_s,
               {{"auc", auc}, {"below", review_->below}, {"decision", decision}});
  char text[160];
  std::snprintf(text, sizeof text, "Calibration review: %s (AUC %.3f%s)", decision, auc,
                review_->below ? ", below the minimum" : "");
  cycle.annotate(cycle.eeg_sample, text);
  calibration_.reviewed(decision, auc, cycle.time_s);
  reasons_.status.clear();
  if (go_online) {
    goOnline(cycle);
    return;
  }
  review_.reset();
  ++calibration_round_;
  s_.tell.say(cycle.time_s, Severity::Info,
              "recalibrating: a new calibration run; training will use its selections only");
  calibration_.restart();
  paradigm_.recalibrate();
  handleEvents(cycle);
}

const WorldObjectSettings& ParadigmStage::objectOfCode(int code) const {
  return settings_.world.objects[slots_.at(static_cast<size_t>(code - 1))];
}

void ParadigmStage::chooseSelectableObjects(Cycle& cycle) {
  // In view: a fresh pose (an object the robot moved, seen since it was moved). An object hidden,
  // gone or not tracked lately is not offered.
  std::vector<size_t> slots;
  std::vector<int> ids;
  for (size_t i = 0; i < settings_.world.objects.size(); ++i) {
    const int id = settings_.world.objects[i].id;
    if (cycle.record.tracking.fresh(id, cycle.time_s)) {
      slots.push_back(i);
      ids.push_back(id);
    }
  }
  if (slots == slots_) return;
  if (slots.size() < 2) {
    s_.log.write("objects_in_view", cycle.time_s,
                 {{"objects", ids}, {"kept", "fewer than 2 in view"}});
    return;
  }
  slots_ = slots;
  paradigm_.setObjectCount(static_cast<int>(slots.size()));
  nameObjects();
  s_.log.write("objects_in_view", cycle.time_s, {{"objects", ids}});
  // The codes now stand for other objects: the recording says so from here on.
  cycle.annotate(cycle.eeg_sample, "StimulusCodeMap " + stimulusCodeMap(settings_.world, slots_));
}

std::optional<int> ParadigmStage::objectOnCell(std::pair<int, int> cell, const Cycle& cycle) const {
  const cv::Vec3d centre = settings_.world.grid.cellCentre(cell.first, cell.second);
  const double half = 0.5 * settings_.world.grid.cell_m;
  const auto& world = cycle.record.tracking.world;
  if (!world) return std::nullopt;
  const auto& grasped = cycle.record.robot.grasped;
  for (const vision::ObjectState& o : world->objects()) {
    if (grasped && o.id == *grasped) continue;
    const cv::Vec3d p = o.T_robot_object.translation;
    if (std::abs(p[0] - centre[0]) < half && std::abs(p[1] - centre[1]) < half) return o.id;
  }
  return std::nullopt;
}

std::set<int> ParadigmStage::intendedCodes(bool objects) const {
  const TrialRecord* trial = trials_.find(paradigm_.trial());
  if (!trial) return {};
  if (!objects)
    return {trial->intended_cell.first, settings_.world.grid.rows + trial->intended_cell.second};
  for (size_t k = 0; k < slots_.size(); ++k) {
    if (settings_.world.objects[slots_[k]].id == trial->intended_object)
      return {static_cast<int>(k) + 1};
  }
  return {};
}

std::set<int> ParadigmStage::attendedCodes(bool objects, const Cycle& cycle) {
  const TrialRecord& trial = trials_.at(paradigm_.trial());
  std::set<int> codes = intendedCodes(objects);
  if (!codes.empty()) return codes;
  s_.tell.say(cycle.time_s, Severity::Warning,
              "trial " + std::to_string(trial.trial) + ": the intended object " +
                  std::to_string(trial.intended_object) + " is not in view, so it does not flash");
  s_.log.write("intended_not_in_view", cycle.time_s,
               {{"trial", trial.trial}, {"object", trial.intended_object}});
  return {};
}

void ParadigmStage::judgeFeedback(Cycle& cycle) {
  if (!paradigm_.awaitingErrpVerdict()) return;
  const double time = cycle.time_s;
  const bool objects = paradigm_.phase() == bci::Phase::ObjectSelected;
  nlohmann::json fields = {{"trial", paradigm_.trial()}, {"kind", objects ? "object" : "cell"}};
  if (const auto error = errp_.shownError()) fields["correct"] = !*error;
  const auto& model = cycle.record.errp.model;
  if (!model) {
    fields["veto"] = false;
    fields["why"] = "no ErrP classifier: executed";
    s_.log.write("errp_decision", time, fields);
    trials_.markVerdict(paradigm_.trial(), false);
    paradigm_.errpVerdict(false);
    return;
  }
  const auto verdict = errp_.judge(*model, time);
  if (!verdict) return;  // its epoch is not complete yet
  fields["score"] = verdict->score;
  fields["prior_error"] = verdict->prior_error;
  fields["posterior_error"] = verdict->posterior_error;
  fields["threshold"] = errp_.threshold();
  fields["veto"] = verdict->veto;
  s_.log.write("errp_decision", time, fields);
  char text[96];
  std::snprintf(text, sizeof text, "ErrP %s (posterior of error %.2f)",
                verdict->veto ? "rejected the selection" : "accepted the selection",
                verdict->posterior_error);
  cycle.annotate(cycle.eeg_sample, text);
  if (verdict->veto)
    s_.tell.say(time, Severity::Info,
                std::string(text) + " in trial " + std::to_string(paradigm_.trial()));
  trials_.markVerdict(paradigm_.trial(), verdict->veto);
  paradigm_.errpVerdict(verdict->veto);
}

void ParadigmStage::decideIfReady(const Cycle& cycle) {
  const bci::Phase phase = paradigm_.phase();
  const bool online = phase == bci::Phase::ObjectFlashing || phase == bci::Phase::CellFlashing;
  // The P300 stage's counts are this selection's once it has started it (the cycle after).
  const P300Part& p300 = cycle.record.p300;
  const bool current = p300.selection == selection_;
  const int sequences = current ? p300.sequences : 0;
  const bool scored = current && p300.presented > 0 && p300.scored >= p300.presented;
  // Dynamic stopping: certain enough after the minimum number of scored sequences.
  const bci::ParadigmSettings& p = settings_.paradigm;
  // While the model learnt from use is not trusted the selection is data to learn from: all its
  // sequences.
  if (online && p300.model && !untrusted(cycle) && p.certainty > 0.0 &&
      sequences >= p.min_sequences && p300.decision.certainty >= p.certainty) {
    paradigm_.requestStopFlashing();
    if (!p300.decision.codes.empty())
      stopped_certain_ = std::pair{selection_, *p300.decision.codes.begin()};
  }
  if (paradigm_.awaitingDecision() && scored) paradigm_.decide(p300.decision);
}

bool ParadigmStage::untrusted(const Cycle& cycle) const {
  const auto& learning = cycle.record.p300.learning;
  return settings_.learns && !(learning && learning->trusted);
}

void ParadigmStage::followLearning(const Cycle& cycle) {
  const auto& learning = cycle.record.p300.learning;
  if (settings_.learns) judgeHeldSelection(cycle);
  if (!learning || learning == learning_seen_) return;
  learning_seen_ = learning;
  // Trusted (judged once per fit), a selection goes on until certain enough for the arm: dynamic
  // stopping ends it. Untrusted, it flashes the learning's sequences: evidence for the next fit.
  using Sequences = bci::Paradigm::ObjectSequences;
  if (settings_.learns)
    paradigm_.setObjectSequences(!learning->trusted                   ? Sequences::Learning
                                 : settings_.paradigm.certainty > 0.0 ? Sequences::Trusted
                                                                      : Sequences::Usual);
  const auto object = [this](const std::map<int, int>& codes, int number) -> std::optional<int> {
    const auto code = codes.find(number);
    const auto selection = learnt_.find(number);
    if (code == codes.end() || selection == learnt_.end()) return std::nullopt;
    const auto& ids = selection->second.ids;
    if (code->second < 1 || code->second > static_cast<int>(ids.size())) return std::nullopt;
    return ids[static_cast<size_t>(code->second - 1)];
  };
  for (const auto& [number, selection] : learnt_) {
    TrialRecord* trial = trials_.find(selection.trial);
    if (!trial) continue;
    trial->post_hoc_object = object(learning->post_hoc, number);
    if (learning->adapting) trial->frozen_object = object(learning->frozen, number);
  }
}

void ParadigmStage::judgeHeldSelection(const Cycle& cycle) {
  const auto& learning = cycle.record.p300.learning;
  if (paradigm_.phase() != bci::Phase::ObjectSelected || !learning || !selection_objects_) return;
  // The selection shown now (selection_) is being fitted in with the rest, or will be. The arm acts
  // on it only when that fit is trusted and decodes it as it was shown (the model that decided it
  // online and the one that learnt from it agree), and when the online decision was itself as
  // certain as dynamic stopping asks (when it stopped the selection, or at its end). The fit's
  // own posterior cannot say that: a selection fitted with the rest is explained by the model it
  // helped to make, and almost always looks certain.
  const bool pending =
      learning->awaited_through >= selection_ && learning->fitted_through < selection_;
  const bool fitted = !pending && learning->fitted_through >= selection_;
  const auto post_hoc = learning->post_hoc.find(selection_);
  const bool as_shown =
      post_hoc != learning->post_hoc.end() && stimulus_.selected_object == post_hoc->second;
  const TrialRecord* trial = trials_.find(paradigm_.trial());
  const bool stopped_certain = stopped_certain_ && stopped_certain_->first == selection_ &&
                               stimulus_.selected_object == stopped_certain_->second;
  const bool certain = stopped_certain || (trial && trial->object_certainty >=
                                                        settings_.paradigm.certainty);  // 0: none
  const bool act = fitted && learning->trusted && as_shown && certain;
  const char* why = kArmHeld;
  if (fitted && post_hoc == learning->post_hoc.end() && !learning->error.empty())
    why = kArmHeldFitFailed;
  else if (fitted && learning->trusted && !as_shown)
    why = kArmHeldUnconfirmed;
  else if (fitted && learning->trusted)
    why = kArmHeldUncertain;
  paradigm_.judgeHeldSelection(pending, act, why);
  if (act && !first_trusted_trial_) first_trusted_trial_ = paradigm_.trial();
}

void ParadigmStage::stop(Cycle& cycle, const std::string& /*reason*/) {
  followLearning(cycle);  // the P300 stage's last fit
}

void ParadigmStage::report(nlohmann::json& summary) const {
  const int cells = settings_.world.grid.rows * settings_.world.grid.columns;
  summary.update(
      trialsSummary(trials_.trials(), static_cast<int>(settings_.world.objects.size()), cells));
  calibration_.summarise(summary);
  // Counts as they happened: a selection retaken is one selection more, a sequence begun again
  // after an interruption is only more flashes of its selection.
  if (summary.contains("calibration")) {
    summary["calibration"]["retakes"] = paradigm_.calibrationRetakes();
    summary["calibration"]["reflashed_sequences"] = paradigm_.reflashedSequences();
  }
  view_watch_.report(summary);
  if (settings_.paradigm.errp) errp_.report(summary["errp"]);
  if (learnt_.empty() || !learning_seen_) return;
  // Learning from use: the online decisions beside the post-hoc ones, and where the arm went.
  nlohmann::json& out = summary["learning"];
  int made = 0, online_right = 0, post_hoc_made = 0, post_hoc_right = 0, held = 0, wrong_arm = 0;
  int half_made = 0, half_post_hoc = 0, half_frozen = 0;
  const auto& all = trials_.trials();
  for (size_t i = 0; i < all.size(); ++i) {
    const TrialRecord& t = all[i];
    held += t.arm_held;
    wrong_arm += t.robot_object && *t.robot_object != t.intended_object;
    if (t.post_hoc_object) {  // every selection the last fit decoded, one without a model too
      ++post_hoc_made;
      post_hoc_right += *t.post_hoc_object == t.intended_object;
    }
    if (t.selections.empty() || !t.selections.front().object) continue;
    ++made;
    online_right += t.selections.front().object_id == t.intended_object;
    if (learning_seen_->adapting && 2 * i >= all.size() && t.post_hoc_object && t.frozen_object) {
      ++half_made;
      half_post_hoc += *t.post_hoc_object == t.intended_object;
      half_frozen += *t.frozen_object == t.intended_object;
    }
  }
  out["mode"] = learning_seen_->adapting ? "adapt" : "none";
  out["object_selections"] = made;
  out["online_right"] = online_right;
  out["post_hoc"] = {{"decoded", post_hoc_made}, {"right", post_hoc_right}};
  out["trials_arm_held"] = held;
  out["wrong_robot_objects"] = wrong_arm;
  out["first_trusted_trial"] =
      first_trusted_trial_ ? nlohmann::json(*first_trusted_trial_) : nlohmann::json(nullptr);
  if (learning_seen_->adapting) {
    // Did adapting help? The last half's object selections decoded post hoc by the adapted
    // model and by the calibrated one, frozen, on the same epochs.
    out["last_half"] = {{"selections", half_made},
                        {"adapted_right", half_post_hoc},
                        {"frozen_right", half_frozen},
                        {"adapting_helped", half_post_hoc > half_frozen}};
  }
}

}  // namespace arbci::session
