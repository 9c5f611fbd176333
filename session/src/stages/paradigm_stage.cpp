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
      paradigm_(std::make_unique<bci::Paradigm>(
          settings_.paradigm, static_cast<int>(settings_.world.objects.size()),
          settings_.world.grid.rows, settings_.world.grid.columns, settings_.seed)) {
  slots_ = allSlots(settings_.world);
  nameObjects();
}

void ParadigmStage::nameObjects() {
  std::vector<int> ids;
  for (size_t slot : slots_) ids.push_back(settings_.world.objects[slot].id);
  paradigm_->setObjectNames(ids);
}

std::optional<int> ParadigmStage::selectedObjectId() const {
  const int trial = paradigm_->trial();
  if (trial < 1 || trial > static_cast<int>(trials_.size())) return std::nullopt;
  const int id = trials_[static_cast<size_t>(trial - 1)].selected_object;
  return id > 0 ? std::optional<int>(id) : std::nullopt;
}

void ParadigmStage::step(Cycle& cycle) {
  ParadigmPart& part = out(cycle);
  part = ParadigmPart{};
  // A new feedback's score is awaited; a score that came is the feedback's.
  if (cycle.record.presentation.feedback) errp_score_.reset();
  if (cycle.record.errp.score) errp_score_ = cycle.record.errp.score->second;
  if (cycle.record.presentation.shown && awaiting_p300_) {
    // What training on a worker thread costs the display.
    const double at = cycle.record.presentation.at_s;
    if (watch_last_at_) {
      ++watch_frames_;
      watch_longest_s_ = std::max(watch_longest_s_, at - *watch_last_at_);
    }
    watch_last_at_ = at;
  }
  for (const Request& request : cycle.record.requests) act(request, cycle);
  takeRobotNotes(cycle);
  watchGrasp(cycle);
  collectTraining(cycle);
  stimulus_ = paradigm_->frame(cycle.frame, cycle.due_s);
  withholdStaleFlashes(cycle);
  handleEvents(cycle);
  decideIfReady(cycle);
  judgeFeedback(cycle);
  watchEegSource(cycle);
  watchWithheldFlashes(cycle);
  publish(cycle);
}

void ParadigmStage::publish(Cycle& cycle) {
  ParadigmPart& part = out(cycle);
  part.phase = paradigm_->phase();
  part.interrupted = paradigm_->interrupted();
  part.trial = paradigm_->trial();
  part.sequence = paradigm_->sequence();
  part.errp_awaited = paradigm_->awaitingErrpVerdict();
  part.stimulus = stimulus_;
  part.slots = slots_;
  part.selected_object = selectedObjectId();
  part.trials = std::make_shared<const std::vector<TrialRecord>>(trials_);
  part.calibration = calibration_report_;
  part.status = status_;
}

void ParadigmStage::act(const Request& request, Cycle& cycle) {
  const double time = cycle.time_s;
  if (std::holds_alternative<BeginRequest>(request)) {
    if (paradigm_->phase() != bci::Phase::Setup) return;
    chooseSelectableObjects(cycle);
    paradigm_->start(!cycle.record.p300.model);
  } else if (std::holds_alternative<PauseRequest>(request)) {
    stopped_because_ = "paused by the experimenter";
    paradigm_->pause();
  } else if (std::holds_alternative<ResumeRequest>(request)) {
    if (paradigm_->interrupted()) cycle.post(RobotResetIfLatchedRequest{time});
    paradigm_->resume();
  } else if (std::holds_alternative<AbortRequest>(request)) {
    paradigm_->abort();
  } else if (std::holds_alternative<EmergencyStopRequest>(request)) {
    // The session sent the arm its STOP already; the paradigm stops where it is.
    stopped_because_ = "emergency stop";
    paradigm_->emergencyStop();
  } else if (std::holds_alternative<RetryStepRequest>(request)) {
    s_.log.write("recovery", time, {{"action", "retry step"}, {"trial", paradigm_->trial()}});
    cycle.post(RobotResetIfLatchedRequest{time});
    retrying_ = true;
    paradigm_->retryStep();
    handleEvents(cycle);  // the robot's command goes out with this cycle's requests
    retrying_ = false;
  } else if (std::holds_alternative<SkipTrialRequest>(request)) {
    s_.log.write("recovery", time, {{"action", "skip trial"}, {"trial", paradigm_->trial()}});
    cycle.post(RobotResetIfLatchedRequest{time});
    paradigm_->skipTrial();
    handleEvents(cycle);
  } else if (std::holds_alternative<EndSessionRequest>(request)) {
    const bci::Phase phase = paradigm_->phase();
    s_.log.write("recovery", time, {{"action", "end session"}});
    paradigm_->abort();
    cycle.end(std::string("ended by the experimenter in: ") + bci::toString(phase),
              endKindOf("", phase));
  }
}

TrialRecord& ParadigmStage::currentTrial() {
  const int number = std::max(1, paradigm_->trial());
  while (static_cast<int>(trials_.size()) < number) {
    TrialRecord r;
    r.trial = static_cast<int>(trials_.size()) + 1;
    const TrialIntent& intent = settings_.intended[static_cast<size_t>(r.trial - 1)];
    r.intended_object = intent.object;
    r.intended_cell = {intent.row, intent.column};
    r.started_s = last_trial_end_;
    trials_.push_back(r);
  }
  return trials_[static_cast<size_t>(number - 1)];
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
  TrialRecord& trial = currentTrial();
  if (trial.robot_object == sight->object)
    trial.grasp_pose_age_max_s = sight->never_seen ? -1.0 : sight->max_age_s;
}

void ParadigmStage::takeRobotNotes(Cycle& cycle) {
  using Kind = RobotPart::Note::Kind;
  for (const RobotPart::Note& note : cycle.record.robot.notes) {
    switch (note.kind) {
      case Kind::Outcome:
        currentTrial().outcome = note.text;
        break;
      case Kind::Placement:
        trials_.at(static_cast<size_t>(note.trial - 1)).placement_error_m = note.error_m;
        break;
      case Kind::Finished:
        paradigm_->robotFinished(note.success, note.text);
        break;
      case Kind::PutDownEnded:
        // Home after a put-down, the table seen again: the next trial offers what is in view.
        chooseSelectableObjects(cycle);
        paradigm_->robotFinished(true, "");
        break;
    }
  }
}

void ParadigmStage::collectTraining(Cycle& cycle) {
  if (!awaiting_p300_ && !awaiting_errp_) return;
  const double time = cycle.time_s;
  const P300Part& p300 = cycle.record.p300;
  const ErrpPart& errp = cycle.record.errp;
  if (awaiting_p300_ && !p300.training_error.empty()) {
    awaiting_p300_ = awaiting_errp_ = false;
    s_.log.write("training_failed", time, {{"reason", p300.training_error}});
    s_.tell.say(time, Severity::Error, "training failed: " + p300.training_error);
    status_ = "training failed: " + p300.training_error;
    paradigm_->modelTrained(false, p300.training_error);
    return;
  }
  if (awaiting_p300_ && p300.trained) {
    awaiting_p300_ = false;
    calibration_report_ = p300.trained;
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
  if (awaiting_p300_ || awaiting_errp_) return;
  // Both classifiers trained: one model file, the ErrP classifier inside the P300 one's.
  bci::P300Model model = *p300.model;
  if (errp_report_ && errp.model) {
    model.errp = errp.model;
    model.errp_auc = errp_report_->auc;
  }
  model.save(settings_.model_file);
  s_.log.write("trained", time,
               {{"method", settings_.classifier_method},
                {"training_s", time - training_since_},
                {"frames_while_training", watch_frames_},
                {"longest_frame_ms", 1000.0 * watch_longest_s_},
                {"median_frame_ms", cycle.record.presentation.median_frame_ms.value_or(0.0)},
                {"auc", calibration_report_->auc},
                {"accuracy_by_sequences", calibration_report_->accuracy},
                {"selections_used", trained_on_},
                {"selections_left_out", p300.left_out}});
  {
    const bci::EvaluationReport& r = *calibration_report_;
    char text[200];
    std::snprintf(text, sizeof text,
                  "classifier trained (%s): cross-validated AUC %.3f [%.3f, %.3f], accuracy "
                  "%.0f %% after %zu sequences",
                  settings_.classifier_method.c_str(), r.auc, r.auc_interval.low,
                  r.auc_interval.high, r.accuracy.empty() ? 0.0 : 100.0 * r.accuracy.back(),
                  r.accuracy.size());
    s_.tell.say(time, Severity::Info, text);
    if (!retakes_.empty()) {
      std::string cut;
      for (const Retake& r : retakes_)
        cut += (cut.empty() ? "" : ", ") + std::to_string(r.selection) + " (" + r.reason +
               ", retaken as " + std::to_string(r.retaken_as) + ")";
      s_.tell.say(time, Severity::Info,
                  "trained on " + std::to_string(trained_on_.size()) +
                      " whole calibration selections; left out, interrupted: " + cut);
    }
  }
  if (settings_.paradigm.errp) {
    if (errp_report_) {
      s_.log.write("errp_trained", time,
                   {{"auc", errp_report_->auc},
                    {"auc_95", {errp_report_->auc_interval.low, errp_report_->auc_interval.high}},
                    {"error_feedbacks", errp_report_->target_flashes},
                    {"correct_feedbacks", errp_report_->other_flashes}});
    } else {
      s_.log.write("errp_training_failed", time, {{"reason", errp_failure_}});
      s_.tell.say(time, Severity::Warning,
                  "no ErrP classifier (" + errp_failure_ +
                      "): selections are executed without an ErrP check");
    }
  }
  chooseSelectableObjects(cycle);
  last_trial_end_ = time;  // the first trial's time counts from here
  paradigm_->modelTrained(true, "");
}

const WorldObjectSettings& ParadigmStage::objectOfCode(int code) const {
  return settings_.world.objects[slots_.at(static_cast<size_t>(code - 1))];
}

void ParadigmStage::withholdStaleFlashes(Cycle& cycle) {
  const TrackingPart& tracking = cycle.record.tracking;
  const bool objects = stimulus_.phase == bci::Phase::ObjectFlashing ||
                       stimulus_.phase == bci::Phase::CalibrationFlashing;
  std::set<int> stale;
  for (size_t k = 0; k < slots_.size(); ++k) {
    const int id = settings_.world.objects[slots_[k]].id;
    if (!tracking.fresh(id, cycle.time_s)) stale.insert(id);
    if (objects && stale.count(id)) stimulus_.lit.erase(static_cast<int>(k) + 1);
  }
  // The recording says when an offered object's tracking is lost and regained (once started).
  for (int id : stale) {
    if (!stale_.count(id) && paradigm_->phase() != bci::Phase::Setup)
      cycle.annotate(cycle.eeg_sample, "Tracking lost object " + std::to_string(id));
  }
  for (int id : stale_) {
    if (!stale.count(id) && paradigm_->phase() != bci::Phase::Setup)
      cycle.annotate(cycle.eeg_sample, "Tracking regained object " + std::to_string(id));
  }
  stale_ = std::move(stale);
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
  paradigm_->setObjectCount(static_cast<int>(slots.size()));
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
  const int number = paradigm_->trial();
  if (number < 1 || number > static_cast<int>(trials_.size())) return {};
  const TrialRecord& trial = trials_[static_cast<size_t>(number - 1)];
  if (!objects)
    return {trial.intended_cell.first, settings_.world.grid.rows + trial.intended_cell.second};
  for (size_t k = 0; k < slots_.size(); ++k) {
    if (settings_.world.objects[slots_[k]].id == trial.intended_object)
      return {static_cast<int>(k) + 1};
  }
  return {};
}

void ParadigmStage::judgeFeedback(Cycle& cycle) {
  if (!paradigm_->awaitingErrpVerdict()) return;
  const double time = cycle.time_s;
  const bool objects = paradigm_->phase() == bci::Phase::ObjectSelected;
  nlohmann::json fields = {{"trial", paradigm_->trial()}, {"kind", objects ? "object" : "cell"}};
  if (shown_error_) fields["correct"] = !*shown_error_;
  const auto& errp = cycle.record.errp.model;
  if (!errp) {
    fields["veto"] = false;
    fields["why"] = "no ErrP classifier: executed";
    s_.log.write("errp_decision", time, fields);
    markVerdict(false);
    paradigm_->errpVerdict(false);
    return;
  }
  const auto score = std::exchange(errp_score_, std::nullopt);
  if (!score) return;  // its epoch is not complete yet
  const double prior = 1.0 - shown_certainty_;
  const double posterior = bci::errorPosterior(errp->score_model, *score, prior);
  const bool veto = posterior > settings_.errp_threshold;
  fields["score"] = *score;
  fields["prior_error"] = prior;
  fields["posterior_error"] = posterior;
  fields["threshold"] = settings_.errp_threshold;
  fields["veto"] = veto;
  s_.log.write("errp_decision", time, fields);
  char text[96];
  std::snprintf(text, sizeof text, "ErrP %s (posterior of error %.2f)",
                veto ? "rejected the selection" : "accepted the selection", posterior);
  cycle.annotate(cycle.eeg_sample, text);
  ++errp_counts_.decisions;
  if (shown_error_) {
    (*shown_error_ ? errp_counts_.wrong_shown : errp_counts_.correct_shown) += 1;
    if (veto) (*shown_error_ ? errp_counts_.wrong_caught : errp_counts_.correct_vetoed) += 1;
  }
  if (veto && vetoed_since_ < 0.0) vetoed_since_ = time;
  if (!veto && vetoed_since_ >= 0.0) {
    errp_counts_.correction_s += time - vetoed_since_;
    vetoed_since_ = -1.0;
  }
  if (veto)
    s_.tell.say(time, Severity::Info,
                std::string(text) + " in trial " + std::to_string(paradigm_->trial()));
  markVerdict(veto);
  paradigm_->errpVerdict(veto);
}

void ParadigmStage::markVerdict(bool veto) {
  const int trial = paradigm_->trial();
  if (trial < 1 || trial > static_cast<int>(trials_.size())) return;
  std::vector<SelectionMade>& made = trials_[static_cast<size_t>(trial - 1)].selections;
  if (!made.empty()) made.back().vetoed = veto;
}

std::set<int> ParadigmStage::attendedCodes(bool objects, const Cycle& cycle) {
  const TrialRecord& trial = currentTrial();
  std::set<int> codes = intendedCodes(objects);
  if (!codes.empty()) return codes;
  s_.tell.say(cycle.time_s, Severity::Warning,
              "trial " + std::to_string(trial.trial) + ": the intended object " +
                  std::to_string(trial.intended_object) + " is not in view, so it does not flash");
  s_.log.write("intended_not_in_view", cycle.time_s,
               {{"trial", trial.trial}, {"object", trial.intended_object}});
  return {};
}

void ParadigmStage::recordSelection(const bci::ParadigmEvent& e, Cycle& cycle) {
  TrialRecord& trial = currentTrial();
  const double selection_s = cycle.record.presentation.selection_s;
  if (e.objects_layout) {
    trial.selected_object = objectOfCode(e.object).id;
    trial.object_certainty = e.certainty;
    trial.object_flashes = selection_flashes_;
    trial.object_selection_s = selection_s;
  } else {
    trial.selected_cell = e.cell;
    trial.cell_certainty = e.certainty;
    trial.cell_flashes = selection_flashes_;
    trial.cell_selection_s = selection_s;
  }
  const bool correct = e.objects_layout ? trial.selected_object == trial.intended_object
                                        : trial.selected_cell == trial.intended_cell;
  SelectionMade made;
  made.object = e.objects_layout;
  made.object_id = e.objects_layout ? trial.selected_object : -1;
  made.cell = e.objects_layout ? std::pair<int, int>{0, 0} : e.cell;
  made.correct = correct;
  trial.selections.push_back(made);
  nlohmann::json fields = {{"trial", trial.trial},
                           {"kind", e.objects_layout ? "object" : "cell"},
                           {"certainty", e.certainty},
                           {"flashes", selection_flashes_},
                           {"correct", correct}};
  if (e.objects_layout) {
    fields["selected"] = trial.selected_object;
    fields["intended"] = trial.intended_object;
  } else {
    fields["selected"] = {e.cell.first, e.cell.second};
    fields["intended"] = {trial.intended_cell.first, trial.intended_cell.second};
  }
  s_.log.write("selection", cycle.time_s, fields);
  cycle.annotate(cycle.eeg_sample,
                 std::string("Selected ") +
                     (e.objects_layout ? "object " + std::to_string(trial.selected_object)
                                       : "cell " + std::to_string(e.cell.first) + "," +
                                             std::to_string(e.cell.second)) +
                     (correct ? " (intended)" : " (not the intended)"));
  if (!correct) {
    s_.tell.say(cycle.time_s, Severity::Info,
                std::string("selection ") + (e.objects_layout ? "of the object" : "of the cell") +
                    " in trial " + std::to_string(trial.trial) +
                    " differs from the intended one; carrying on");
  }
}

void ParadigmStage::handleEvents(Cycle& cycle) {
  using Kind = bci::ParadigmEvent::Kind;
  ParadigmPart& part = out(cycle);
  const double time = cycle.time_s;
  for (const bci::ParadigmEvent& e : paradigm_->takeEvents()) {
    switch (e.kind) {
      case Kind::PhaseChanged:
        s_.log.write("phase", time,
                     {{"phase", bci::toString(e.phase)}, {"text", e.text}, {"trial", e.trial}});
        cycle.annotate(cycle.eeg_sample, bci::kPhaseAnnotation + e.text);
        part.phase_changes.push_back({e.phase, e.trial});
        break;
      case Kind::SelectionStarted: {
        selection_flashes_ = 0;
        std::set<int> attended;
        std::optional<int> target;
        std::optional<int> retake_of;
        if (paradigm_->phase() == bci::Phase::CalibrationCue ||
            paradigm_->phase() == bci::Phase::CalibrationFlashing) {
          attended = e.codes;
          target = *e.codes.begin();
          if (e.retake) {
            retake_of = selection_;
            noteRetake(*target, cycle);
          }
          s_.log.write("calibration_target", time, {{"object", objectOfCode(*target).id}});
        } else {
          attended = attendedCodes(e.objects_layout, cycle);
        }
        ++selection_;
        selection_objects_ = e.objects_layout;
        truth_ = target ? std::set<int>{*target} : attended;
        part.selection_started =
            SelectionStart{selection_,
                           e.objects_layout,
                           e.objects_layout ? paradigm_->objectLayout() : paradigm_->gridLayout(),
                           attended,
                           target,
                           retake_of};
        break;
      }
      case Kind::Flash:
        if (!stimulus_.lit.count(e.code)) {
          // Its object's pose is stale: not shown, so not recorded as a flash either.
          s_.log.write(
              "flash_withheld", time,
              {{"code", e.code}, {"object", objectOfCode(e.code).id}, {"why", "tracking lost"}});
          if (withheld_since_ < 0.0) withheld_since_ = time;
          if (paradigm_->phase() == bci::Phase::CalibrationFlashing)
            pauseCalibrationForView(objectOfCode(e.code).id, cycle);
          break;
        }
        withheld_since_ = -1.0;
        // Stamped when the frame that shows it is presented.
        part.first_shown.push_back(
            {e.code, selection_objects_, truth_.count(e.code) > 0, !truth_.empty(), selection_});
        ++selection_flashes_;
        break;
      case Kind::SelectionMade:
        recordSelection(e, cycle);
        shown_certainty_ = e.certainty;
        errp_score_.reset();  // a score still held is an earlier feedback's, not this one's
        break;
      case Kind::Feedback: {
        FeedbackShown shown{e.codes, e.objects_layout, e.error};
        const bool online = !e.error.has_value();
        if (online) {
          const std::set<int> intended = intendedCodes(e.objects_layout);
          if (!intended.empty()) shown.error = e.codes != intended;
        }
        shown_error_ = online ? shown.error : std::nullopt;
        part.feedback = shown;
        break;
      }
      case Kind::ErrpCorrection:
        s_.log.write("errp_correction", time,
                     {{"trial", e.trial},
                      {"kind", e.objects_layout ? "object" : "cell"},
                      {"action", e.text}});
        if (e.text == "runner-up") ++errp_counts_.runner_up;
        if (e.text == "repeat") ++errp_counts_.repeats;
        if (e.text == "skip" || e.text == "return") {
          ++errp_counts_.skipped_trials;
          if (vetoed_since_ >= 0.0) errp_counts_.correction_s += time - vetoed_since_;
          vetoed_since_ = -1.0;
        }
        break;
      case Kind::TrainModel:
        // On worker threads: the cycle (and the window) goes on; collectTraining() takes it.
        cycle.post(TrainRequest{settings_.classifier_method});
        awaiting_p300_ = true;
        awaiting_errp_ = settings_.paradigm.errp;
        errp_report_.reset();
        errp_failure_.clear();
        training_since_ = time;
        watch_frames_ = 0;
        watch_longest_s_ = 0.0;
        watch_last_at_.reset();
        if (cycle.record.presentation.shown) watch_last_at_ = cycle.record.presentation.at_s;
        s_.log.write("training_started", time, {{"method", settings_.classifier_method}});
        break;
      case Kind::RobotGrasp: {
        const int id = objectOfCode(e.object).id;
        const auto& world = cycle.record.tracking.world;
        const auto seen = world ? world->object(id) : std::nullopt;
        const auto holding = cycle.record.robot.holding();
        if (seen && !cycle.record.tracking.fresh(id, time) && holding != id) {
          // Never a grasp at a stale pose: the experimenter retries once the cameras see it.
          char why[160];
          std::snprintf(why, sizeof why,
                        "object %d: tracking lost (pose %.1f s old), not grasped; Retry step "
                        "once it is seen again",
                        id, seen->age(time));
          currentTrial().outcome = why;
          status_ = why;
          s_.tell.say(time, Severity::Error, why);
          paradigm_->robotFinished(false, why);
          break;
        }
        if (retrying_ && holding == id) {
          // Stopped after the gripper closed: the grasp is done.
          s_.log.write("robot_step_done", time, {{"step", "grasp"}, {"object", id}});
          paradigm_->robotFinished(true, "");
          break;
        }
        if (!seen) {
          // Never a grasp at a stale position: a moved object is grasped once seen again.
          currentTrial().outcome = "object " + std::to_string(id) +
                                   " is not in view (never seen, or not since the robot moved it)";
          paradigm_->robotFinished(false, currentTrial().outcome);
          break;
        }
        cycle.post(GraspRequest{id, seen->T_robot_object.translation, time});
        currentTrial().robot_object = id;
        break;
      }
      case Kind::RobotDrop: {
        if (retrying_ && !cycle.record.robot.holding()) {
          // Stopped after the object was let go: the arm goes home, and the put-down ends.
          cycle.post(FinishPutDownRequest{time});
          break;
        }
        const auto other = objectOnCell(e.cell, cycle);
        if (other) {
          // Never onto another object: it goes back where it came from, and the trial says why.
          currentTrial().outcome = "returned: cell " + std::to_string(e.cell.first) + "," +
                                   std::to_string(e.cell.second) + " is taken by object " +
                                   std::to_string(*other);
          s_.tell.say(
              time, Severity::Warning,
              "trial " + std::to_string(currentTrial().trial) + ": " + currentTrial().outcome);
        }
        if (e.give_back) {
          currentTrial().outcome = "returned: the ErrP rejected every cell selected";
          s_.tell.say(
              time, Severity::Warning,
              "trial " + std::to_string(currentTrial().trial) + ": " + currentTrial().outcome);
        }
        cycle.post(
            DropRequest{currentTrial().trial, e.cell, other.has_value() || e.give_back, time});
        if (other || e.give_back)
          currentTrial().robot_returned = true;
        else
          currentTrial().robot_cell = e.cell;
        break;
      }
      case Kind::RobotStop:
        cycle.post(RobotStopRequest{time});
        break;
      case Kind::TrialDone:
        if (e.trial >= 1 && e.trial <= static_cast<int>(trials_.size())) {
          TrialRecord& done = trials_[static_cast<size_t>(e.trial - 1)];
          done.ended_s = time;
          // Ended by the experimenter (skipped, or resumed after a stop): the record says so.
          if (!e.text.empty())
            done.outcome = done.outcome == "incomplete" ? e.text : done.outcome + "; " + e.text;
        }
        last_trial_end_ = time;
        s_.log.write("trial_done", time, {{"trial", e.trial}, {"text", e.text}});
        if (e.trial >= 1 && e.trial <= static_cast<int>(trials_.size()))
          s_.tell.say(time, Severity::Info,
                      selectionLine(trials_[static_cast<size_t>(e.trial - 1)]));
        break;
    }
  }
}

void ParadigmStage::decideIfReady(const Cycle& cycle) {
  const bci::Phase phase = paradigm_->phase();
  const bool online = phase == bci::Phase::ObjectFlashing || phase == bci::Phase::CellFlashing;
  // The P300 stage's counts are this selection's once it has started it (the cycle after).
  const P300Part& p300 = cycle.record.p300;
  const bool current = p300.selection == selection_;
  const int sequences = current ? p300.sequences : 0;
  const bool scored = current && p300.presented > 0 && p300.scored >= p300.presented;
  // Dynamic stopping: certain enough after the minimum number of scored sequences.
  const bci::ParadigmSettings& p = settings_.paradigm;
  if (online && p300.model && p.certainty > 0.0 && sequences >= p.min_sequences &&
      p300.decision.certainty >= p.certainty) {
    paradigm_->requestStopFlashing();
  }
  if (paradigm_->awaitingDecision() && scored) paradigm_->decide(p300.decision);
}

void ParadigmStage::watchEegSource(Cycle& cycle) {
  using bci::Phase;
  const Phase phase = paradigm_->phase();
  const std::string& fault = cycle.record.eeg.fault;
  const double time = cycle.time_s;
  if (!fault.empty()) {
    eeg_ok_since_ = -1.0;
    // Flashing (or cueing, or showing feedback) without EEG would decide on nothing: the
    // paradigm waits. The robot's own steps need no EEG and go on.
    const bool needs_eeg = phase == Phase::CalibrationCue || phase == Phase::CalibrationFlashing ||
                           phase == Phase::CalibrationFeedback || phase == Phase::ObjectFlashing ||
                           phase == Phase::CellFlashing || phase == Phase::ObjectSelected ||
                           phase == Phase::CellSelected;
    if (!paused_for_eeg_ && needs_eeg) {
      stopped_because_ = "EEG source fault";
      paradigm_->pause();
      paused_for_eeg_ = true;
      status_ = "paused: " + fault;
      s_.log.write("paused", time, {{"reason", "EEG source fault"}, {"fault", fault}});
      s_.tell.say(time, Severity::Error,
                  "paused: " + fault + " (resumes 2 s after the EEG is back)");
    }
    return;
  }
  if (!paused_for_eeg_) return;
  if (phase != Phase::Paused) {
    paused_for_eeg_ = false;  // the experimenter resumed or ended it
    return;
  }
  if (eeg_ok_since_ < 0.0) eeg_ok_since_ = time;
  // Two seconds of signal again, then the sequence starts over (epochs touching the gap, and a
  // second before their window, are discarded).
  if (time - eeg_ok_since_ >= 2.0) {
    paradigm_->resume();
    paused_for_eeg_ = false;
    status_.clear();
    s_.log.write("resumed", time, {{"reason", "EEG source delivering again"}});
    s_.tell.say(time, Severity::Info, "resumed: the EEG source delivers again");
  }
}

void ParadigmStage::watchWithheldFlashes(Cycle& cycle) {
  using bci::Phase;
  const Phase phase = paradigm_->phase();
  const double time = cycle.time_s;
  if (paused_for_view_) {
    if (phase != Phase::Paused) {
      paused_for_view_ = false;  // the experimenter resumed or ended it
      withheld_since_ = -1.0;
      return;
    }
    in_view_since_ = stale_.empty() ? (in_view_since_ < 0.0 ? time : in_view_since_) : -1.0;
    if (in_view_since_ >= 0.0 && time - in_view_since_ >= 1.0) {
      paradigm_->resume();
      paused_for_view_ = false;
      withheld_since_ = -1.0;
      status_.clear();
      s_.log.write("resumed", time, {{"reason", "the objects are in view again"}});
      s_.tell.say(time, Severity::Info, "resumed: the objects are in view again");
    } else if (!settings_.experimenter &&
               time - view_paused_at_ >= settings_.paradigm.no_view_pause_s) {
      // Nobody can bring them back into view: the run ends, saying why.
      const std::string reason = viewLostReason("during calibration");
      s_.log.write("paused", time, {{"reason", reason}});
      cycle.end(reason, "aborted");
    }
    return;
  }
  const bool flashing = phase == Phase::ObjectFlashing || phase == Phase::CalibrationFlashing;
  if (!flashing) withheld_since_ = -1.0;
  if (withheld_since_ < 0.0 || time - withheld_since_ < settings_.paradigm.no_view_pause_s) return;
  const std::string reason = viewLostReason("every flash withheld");
  s_.log.write("paused", time, {{"reason", reason}});
  if (!settings_.experimenter) {
    // Nobody can bring them back into view: the run ends, saying why.
    cycle.end(reason, "aborted");
    return;
  }
  pauseForView("no object in view", reason + "; resumes once they are seen again", time);
  s_.tell.say(time, Severity::Error, "paused: " + reason);
}

void ParadigmStage::pauseForView(const std::string& why, const std::string& status, double time) {
  stopped_because_ = why;
  paradigm_->pause();
  paused_for_view_ = true;
  view_paused_at_ = time;
  in_view_since_ = -1.0;
  status_ = "paused: " + status;
}

std::string ParadigmStage::viewLostReason(const std::string& context) const {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", settings_.paradigm.no_view_pause_s);
  std::string lost;
  for (int id : stale_) lost += (lost.empty() ? "" : ", ") + std::to_string(id);
  return std::string(stale_.size() >= slots_.size() ? "no object in view" : "tracking lost") +
         ": the reference marker or objects (" + lost + ") lost for " + seconds +
         " s (paradigm.no_view_pause_s), " + context;
}

void ParadigmStage::pauseCalibrationForView(int object_id, Cycle& cycle) {
  const double time = cycle.time_s;
  const std::string reason = "calibration selection " + std::to_string(selection_) + ": object " +
                             std::to_string(object_id) +
                             "'s flash withheld (tracking lost); the selection is retaken once "
                             "every object has been in view for 1 s";
  pauseForView("tracking lost: object " + std::to_string(object_id), reason, time);
  s_.log.write("paused", time, {{"reason", reason}});
  s_.tell.say(time, Severity::Warning, "paused: " + reason);
}

void ParadigmStage::noteRetake(int target_code, Cycle& cycle) {
  Retake r{selection_, objectOfCode(target_code).id,
           stopped_because_.empty() ? "interrupted" : stopped_because_, selection_ + 1};
  s_.log.write("calibration_retake", cycle.time_s,
               {{"selection", r.selection},
                {"object", r.object},
                {"reason", r.reason},
                {"retaken_as", r.retaken_as}});
  cycle.annotate(cycle.eeg_sample, "Calibration selection " + std::to_string(r.selection) +
                                       " interrupted (" + r.reason + "): left out of training, " +
                                       "retaken as selection " + std::to_string(r.retaken_as));
  s_.tell.say(cycle.time_s, Severity::Info,
              "calibration selection " + std::to_string(r.selection) + " (object " +
                  std::to_string(r.object) + ") interrupted (" + r.reason +
                  "): cued again as selection " + std::to_string(r.retaken_as) +
                  "; training leaves the interrupted flashes out");
  retakes_.push_back(r);
}

void ParadigmStage::report(nlohmann::json& summary) const {
  const int cells = settings_.world.grid.rows * settings_.world.grid.columns;
  summary.update(trialsSummary(trials_, static_cast<int>(settings_.world.objects.size()), cells));
  if (calibration_report_) {
    summary["calibration"] = {{"selections", calibration_report_->selections.size()},
                              {"selections_used", trained_on_},
                              {"auc", calibration_report_->auc},
                              {"accuracy_by_sequences", calibration_report_->accuracy}};
  }
  if (!retakes_.empty()) {
    nlohmann::json& retaken = summary["calibration"]["retaken"];
    for (const Retake& r : retakes_) {
      retaken.push_back({{"selection", r.selection},
                         {"object", r.object},
                         {"reason", r.reason},
                         {"retaken_as", r.retaken_as}});
    }
  }
  if (!settings_.paradigm.errp) return;
  const ErrpCounts& c = errp_counts_;
  summary["errp"].update({{"threshold", settings_.errp_threshold},
                          {"decisions", c.decisions},
                          {"wrong_selections", c.wrong_shown},
                          {"wrong_caught", c.wrong_caught},
                          {"correct_selections", c.correct_shown},
                          {"correct_vetoed", c.correct_vetoed},
                          {"runner_up", c.runner_up},
                          {"repeated", c.repeats},
                          {"trials_skipped", c.skipped_trials},
                          {"correction_s", c.correction_s}});
}

}  // namespace arbci::session
