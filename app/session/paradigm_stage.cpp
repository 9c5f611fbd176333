#include "session/paradigm_stage.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include "session/hmd_composition.h"
#include "session/trial_intents.h"

namespace arbci::app {

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

ParadigmStageSettings ParadigmStageSettings::of(const SessionConfig& config) {
  return {config.paradigm,        config.world,         config.classifier_method,
          intendedTrials(config), config.eeg.seed + 11, config.errp.threshold};
}

ParadigmStage::ParadigmStage(const ParadigmStageSettings& settings, const CycleContext& now,
                             bool wait_for_training, std::filesystem::path model_file,
                             Services services)
    : settings_(settings),
      now_(now),
      wait_for_training_(wait_for_training),
      model_file_(std::move(model_file)),
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

void ParadigmStage::start() {
  if (paradigm_->phase() != bci::Phase::Setup) return;
  chooseSelectableObjects();
  paradigm_->start(!s_.eeg.hasModel());
}

void ParadigmStage::emergencyStop() {
  s_.log.write("emergency_stop", now_.time_s, {{"by", "experimenter"}});
  paradigm_->emergencyStop();
  // The paradigm asks for the robot's STOP; it goes out now, not a frame later.
  handleEvents();
}

void ParadigmStage::retryStep() {
  retrying_ = true;
  paradigm_->retryStep();
  handleEvents();  // the robot's command goes out now
  retrying_ = false;
}

void ParadigmStage::skipTrial() {
  paradigm_->skipTrial();
  handleEvents();
}

std::optional<int> ParadigmStage::selectedObjectId() const {
  const int trial = paradigm_->trial();
  if (trial < 1 || trial > static_cast<int>(trials_.size())) return std::nullopt;
  const int id = trials_[static_cast<size_t>(trial - 1)].selected_object;
  return id > 0 ? std::optional<int>(id) : std::nullopt;
}

void ParadigmStage::step(CycleContext& cycle) {
  phase_changes_.clear();
  collectTraining();
  stimulus_ = paradigm_->frame(cycle.frame, cycle.due_s);
  withholdStaleFlashes();
  first_shown_.clear();
  feedback_shown_.reset();
  handleEvents();
  decideIfReady();
  judgeFeedback();
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

TrialRecord& ParadigmStage::trial(int number) {
  return trials_.at(static_cast<size_t>(number - 1));
}

void ParadigmStage::robotFinished(bool success, const std::string& why) {
  paradigm_->robotFinished(success, why);
}

void ParadigmStage::putDownEnded() {
  chooseSelectableObjects();
  paradigm_->robotFinished(true, "");
}

void ParadigmStage::collectTraining() {
  if (!s_.eeg.training()) return;
  const double time = now_.time_s;
  try {
    const auto outcome = s_.eeg.trainingResult(wait_for_training_);
    if (!outcome) return;
    calibration_report_ = outcome->report;
    s_.eeg.model()->save(model_file_);
    const StimulusTiming::Watch watch = s_.timing.stopWatch().value_or(StimulusTiming::Watch{});
    s_.log.write("trained", time,
                 {{"method", settings_.classifier_method},
                  {"training_s", time - training_since_},
                  {"frames_while_training", watch.frames},
                  {"longest_frame_ms", 1000.0 * watch.longest_s},
                  {"median_frame_ms", s_.timing.medianFrameIntervalMs().value_or(0.0)},
                  {"auc", calibration_report_->auc},
                  {"accuracy_by_sequences", calibration_report_->accuracy}});
    if (settings_.paradigm.errp) {
      if (outcome->errp_report) {
        s_.log.write(
            "errp_trained", time,
            {{"auc", outcome->errp_report->auc},
             {"auc_95",
              {outcome->errp_report->auc_interval.low, outcome->errp_report->auc_interval.high}},
             {"error_feedbacks", outcome->errp_report->target_flashes},
             {"correct_feedbacks", outcome->errp_report->other_flashes}});
      } else {
        s_.log.write("errp_training_failed", time, {{"reason", outcome->errp_failure}});
        if (s_.progress)
          *s_.progress << "\nwarning: no ErrP classifier (" << outcome->errp_failure
                       << "): selections are executed without an ErrP check\n";
      }
    }
    chooseSelectableObjects();
    last_trial_end_ = time;  // the first trial's time counts from here
    paradigm_->modelTrained(true, "");
  } catch (const std::exception& error) {
    s_.log.write("training_failed", time, {{"reason", error.what()}});
    paradigm_->modelTrained(false, error.what());
  }
}

const WorldObjectSettings& ParadigmStage::objectOfCode(int code) const {
  return settings_.world.objects[slots_.at(static_cast<size_t>(code - 1))];
}

void ParadigmStage::withholdStaleFlashes() {
  const bool objects = stimulus_.phase == bci::Phase::ObjectFlashing ||
                       stimulus_.phase == bci::Phase::CalibrationFlashing;
  std::set<int> stale;
  for (size_t k = 0; k < slots_.size(); ++k) {
    const int id = settings_.world.objects[slots_[k]].id;
    if (!s_.vision.fresh(id, now_.time_s)) stale.insert(id);
    if (objects && stale.count(id)) stimulus_.lit.erase(static_cast<int>(k) + 1);
  }
  // The recording says when an offered object's tracking is lost and regained (once started).
  for (int id : stale) {
    if (!stale_.count(id) && paradigm_->phase() != bci::Phase::Setup)
      s_.eeg.annotate(now_.eeg_sample, "Tracking lost object " + std::to_string(id));
  }
  for (int id : stale_) {
    if (!stale.count(id) && paradigm_->phase() != bci::Phase::Setup)
      s_.eeg.annotate(now_.eeg_sample, "Tracking regained object " + std::to_string(id));
  }
  stale_ = std::move(stale);
}

void ParadigmStage::chooseSelectableObjects() {
  // In view: a fresh pose (an object the robot moved, seen since it was moved). An object hidden,
  // gone or not tracked lately is not offered.
  std::vector<size_t> slots;
  std::vector<int> ids;
  for (size_t i = 0; i < settings_.world.objects.size(); ++i) {
    const int id = settings_.world.objects[i].id;
    if (s_.vision.fresh(id, now_.time_s)) {
      slots.push_back(i);
      ids.push_back(id);
    }
  }
  if (slots == slots_) return;
  if (slots.size() < 2) {
    s_.log.write("objects_in_view", now_.time_s,
                 {{"objects", ids}, {"kept", "fewer than 2 in view"}});
    return;
  }
  slots_ = slots;
  paradigm_->setObjectCount(static_cast<int>(slots.size()));
  nameObjects();
  s_.log.write("objects_in_view", now_.time_s, {{"objects", ids}});
  // The codes now stand for other objects: the recording says so from here on.
  s_.eeg.annotate(now_.eeg_sample, "StimulusCodeMap " + stimulusCodeMap(settings_.world, slots_));
}

std::optional<int> ParadigmStage::objectOnCell(std::pair<int, int> cell) const {
  const cv::Vec3d centre = gridLayoutOf(settings_.world.grid).cellCentre(cell.first, cell.second);
  const double half = 0.5 * settings_.world.grid.cell_m;
  for (const vision::ObjectState& o : s_.vision.world().objects()) {
    if (s_.robot.grasped() && o.id == *s_.robot.grasped()) continue;
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

void ParadigmStage::judgeFeedback() {
  if (!paradigm_->awaitingErrpVerdict()) return;
  const double time = now_.time_s;
  const bool objects = paradigm_->phase() == bci::Phase::ObjectSelected;
  nlohmann::json fields = {{"trial", paradigm_->trial()}, {"kind", objects ? "object" : "cell"}};
  if (shown_error_) fields["correct"] = !*shown_error_;
  if (!s_.eeg.hasErrpModel()) {
    fields["veto"] = false;
    fields["why"] = "no ErrP classifier: executed";
    s_.log.write("errp_decision", time, fields);
    paradigm_->errpVerdict(false);
    return;
  }
  const auto score = s_.eeg.takeErrpScore();
  if (!score) return;  // its epoch is not complete yet
  const double prior = 1.0 - shown_certainty_;
  const double posterior = bci::errorPosterior(s_.eeg.model()->errp->score_model, *score, prior);
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
  s_.eeg.annotate(now_.eeg_sample, text);
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
  if (veto && s_.progress)
    *s_.progress << "\n" << text << " in trial " << paradigm_->trial() << "\n";
  paradigm_->errpVerdict(veto);
}

std::set<int> ParadigmStage::attendedCodes(bool objects) {
  const TrialRecord& trial = currentTrial();
  std::set<int> codes = intendedCodes(objects);
  if (!codes.empty()) return codes;
  std::cerr << "trial " << trial.trial << ": the intended object " << trial.intended_object
            << " is not in view, so it does not flash\n";
  s_.log.write("intended_not_in_view", now_.time_s,
               {{"trial", trial.trial}, {"object", trial.intended_object}});
  return {};
}

void ParadigmStage::recordSelection(const bci::ParadigmEvent& e) {
  TrialRecord& trial = currentTrial();
  if (e.objects_layout) {
    trial.selected_object = objectOfCode(e.object).id;
    trial.object_certainty = e.certainty;
    trial.object_flashes = selection_flashes_;
    trial.object_selection_s = s_.timing.selectionSeconds();
  } else {
    trial.selected_cell = e.cell;
    trial.cell_certainty = e.certainty;
    trial.cell_flashes = selection_flashes_;
    trial.cell_selection_s = s_.timing.selectionSeconds();
  }
  const bool correct = e.objects_layout ? trial.selected_object == trial.intended_object
                                        : trial.selected_cell == trial.intended_cell;
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
  s_.log.write("selection", now_.time_s, fields);
  s_.eeg.annotate(now_.eeg_sample,
                  std::string("Selected ") +
                      (e.objects_layout ? "object " + std::to_string(trial.selected_object)
                                        : "cell " + std::to_string(e.cell.first) + "," +
                                              std::to_string(e.cell.second)) +
                      (correct ? " (intended)" : " (not the intended)"));
  if (!correct && s_.progress) {
    *s_.progress << "\nselection " << (e.objects_layout ? "of the object" : "of the cell")
                 << " in trial " << trial.trial << " differs from the intended one; carrying on\n";
  }
}

void ParadigmStage::handleEvents() {
  using Kind = bci::ParadigmEvent::Kind;
  const double time = now_.time_s;
  for (const bci::ParadigmEvent& e : paradigm_->takeEvents()) {
    switch (e.kind) {
      case Kind::PhaseChanged:
        s_.log.write("phase", time,
                     {{"phase", bci::toString(e.phase)}, {"text", e.text}, {"trial", e.trial}});
        s_.eeg.annotate(now_.eeg_sample, "Phase " + e.text);
        phase_changes_.push_back({e.phase, e.trial});
        break;
      case Kind::SelectionStarted: {
        selection_flashes_ = 0;
        s_.timing.startSelection();
        std::set<int> attended;
        std::optional<int> target;
        if (paradigm_->phase() == bci::Phase::CalibrationCue ||
            paradigm_->phase() == bci::Phase::CalibrationFlashing) {
          attended = e.codes;
          target = *e.codes.begin();
          s_.log.write("calibration_target", time, {{"object", objectOfCode(*target).id}});
        } else {
          attended = attendedCodes(e.objects_layout);
        }
        s_.eeg.startSelection(
            e.objects_layout,
            e.objects_layout ? paradigm_->objectLayout() : paradigm_->gridLayout(), attended,
            target);
        break;
      }
      case Kind::Flash:
        if (!stimulus_.lit.count(e.code)) {
          // Its object's pose is stale: not shown, so not recorded as a flash either.
          s_.log.write(
              "flash_withheld", time,
              {{"code", e.code}, {"object", objectOfCode(e.code).id}, {"why", "tracking lost"}});
          break;
        }
        // Stamped when the frame that shows it is presented.
        first_shown_.push_back(e.code);
        ++selection_flashes_;
        break;
      case Kind::SelectionMade:
        recordSelection(e);
        shown_certainty_ = e.certainty;
        s_.eeg.takeErrpScore();  // a score still held is an earlier feedback's, not this one's
        break;
      case Kind::Feedback: {
        FeedbackShown shown{e.codes, e.objects_layout, e.error};
        const bool online = !e.error.has_value();
        if (online) {
          const std::set<int> intended = intendedCodes(e.objects_layout);
          if (!intended.empty()) shown.error = e.codes != intended;
        }
        shown_error_ = online ? shown.error : std::nullopt;
        feedback_shown_ = shown;
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
        // On a worker thread: the cycle (and the window) goes on; collectTraining() takes it.
        s_.eeg.startTraining(settings_.classifier_method);
        training_since_ = time;
        s_.timing.startWatch();
        s_.log.write("training_started", time, {{"method", settings_.classifier_method}});
        break;
      case Kind::RobotGrasp: {
        const int id = objectOfCode(e.object).id;
        const auto seen = s_.vision.world().object(id);
        if (seen && !s_.vision.fresh(id, time) && s_.robot.holding() != id) {
          // Never a grasp at a stale pose: the experimenter retries once the cameras see it.
          char why[160];
          std::snprintf(why, sizeof why,
                        "object %d: tracking lost (pose %.1f s old), not grasped; Retry step "
                        "once it is seen again",
                        id, seen->age(time));
          currentTrial().outcome = why;
          paradigm_->robotFinished(false, why);
          break;
        }
        if (retrying_ && s_.robot.holding() == id) {
          // Stopped after the gripper closed: the grasp is done.
          s_.log.write("robot_step_done", time, {{"step", "grasp"}, {"object", id}});
          paradigm_->robotFinished(true, "");
          break;
        }
        const auto state = s_.vision.world().object(id);
        if (!state) {
          // Never a grasp at a stale position: a moved object is grasped once seen again.
          currentTrial().outcome = "object " + std::to_string(id) +
                                   " is not in view (never seen, or not since the robot moved it)";
          paradigm_->robotFinished(false, currentTrial().outcome);
          break;
        }
        s_.robot.grasp(id, state->T_robot_object.translation, time);
        break;
      }
      case Kind::RobotDrop: {
        if (retrying_ && !s_.robot.holding()) {
          // Stopped after the object was let go: the arm goes home, and the put-down ends.
          s_.robot.finishPutDown(time);
          break;
        }
        const auto other = objectOnCell(e.cell);
        if (other) {
          // Never onto another object: it goes back where it came from, and the trial says why.
          currentTrial().outcome = "returned: cell " + std::to_string(e.cell.first) + "," +
                                   std::to_string(e.cell.second) + " is taken by object " +
                                   std::to_string(*other);
          std::cerr << "trial " << currentTrial().trial << ": " << currentTrial().outcome << "\n";
        }
        if (e.give_back) {
          currentTrial().outcome = "returned: the ErrP rejected every cell selected";
          std::cerr << "trial " << currentTrial().trial << ": " << currentTrial().outcome << "\n";
        }
        s_.robot.drop(e.cell, other.has_value() || e.give_back, time);
        break;
      }
      case Kind::RobotStop:
        s_.robot.stop(time);
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
        break;
    }
  }
}

void ParadigmStage::decideIfReady() {
  const bci::Phase phase = paradigm_->phase();
  const bool online = phase == bci::Phase::ObjectFlashing || phase == bci::Phase::CellFlashing;
  // Dynamic stopping: certain enough after the minimum number of scored sequences.
  const bci::ParadigmSettings& p = settings_.paradigm;
  if (online && s_.eeg.hasModel() && p.certainty > 0.0 &&
      s_.eeg.scoredSequences() >= p.min_sequences && s_.eeg.decide().certainty >= p.certainty) {
    paradigm_->requestStopFlashing();
  }
  if (paradigm_->awaitingDecision() && s_.eeg.selectionScored()) paradigm_->decide(s_.eeg.decide());
}

}  // namespace arbci::app
