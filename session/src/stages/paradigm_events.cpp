// The paradigm stage's handling of bci::Paradigm's events: each to the record (flashes labelled,
// selections started, feedback), the log and the recording's notes, the trials' records, and the
// requests for the other stages (training, the robot's grasp, put-down and stop).
#include <cstdio>

#include "arbci/bci/selection_marks.h"

#include "arbci/session/stages/paradigm_stage.h"

namespace arbci::session {

void ParadigmStage::handleEvents(Cycle& cycle) {
  using Kind = bci::ParadigmEvent::Kind;
  for (const bci::ParadigmEvent& e : paradigm_.takeEvents()) {
    switch (e.kind) {
      case Kind::PhaseChanged:
        onPhaseChanged(e, cycle);
        break;
      case Kind::SelectionStarted:
        onSelectionStarted(e, cycle);
        break;
      case Kind::Flash:
        onFlash(e, cycle);
        break;
      case Kind::SelectionMade:
        onSelectionMade(e, cycle);
        break;
      case Kind::Feedback:
        onFeedback(e, cycle);
        break;
      case Kind::ErrpCorrection:
        onErrpCorrection(e, cycle);
        break;
      case Kind::TrainModel:
        onTrainModel(cycle);
        break;
      case Kind::RobotGrasp:
        onRobotGrasp(e, cycle);
        break;
      case Kind::RobotDrop:
        onRobotDrop(e, cycle);
        break;
      case Kind::RobotStop:
        cycle.post(RobotStopRequest{cycle.time_s});
        break;
      case Kind::TrialDone:
        onTrialDone(e, cycle);
        break;
    }
  }
}

void ParadigmStage::onPhaseChanged(const bci::ParadigmEvent& e, Cycle& cycle) {
  s_.log.write("phase", cycle.time_s,
               {{"phase", bci::toString(e.phase)}, {"text", e.text}, {"trial", e.trial}});
  cycle.annotate(cycle.eeg_sample, bci::kPhaseAnnotation + e.text);
  cycle.record.paradigm.phase_changes.push_back({e.phase, e.trial, e.text});
  noteInterruption(e, cycle.time_s);
}

// Every pause, E-STOP and robot fault of an online trial, and when it went on, for the summary.
void ParadigmStage::noteInterruption(const bci::ParadigmEvent& e, double time_s) {
  const auto kind = [](bci::Phase p) -> const char* {
    if (p == bci::Phase::Paused) return "paused";
    if (p == bci::Phase::EmergencyStop) return "emergency stop";
    if (p == bci::Phase::RobotFault) return "robot fault";
    return nullptr;
  };
  TrialRecord* trial = trials_.find(e.trial);
  if (!trial) return;
  auto& list = trial->interruptions;
  const char* now = kind(e.phase);
  if (!list.empty() && list.back().resumed_s < 0.0) {
    if (now && list.back().kind == now) return;  // the same one goes on
    list.back().resumed_s = time_s;              // resumed, or another took over
  }
  if (now) list.push_back({now, time_s, -1.0});
}

void ParadigmStage::onSelectionStarted(const bci::ParadigmEvent& e, Cycle& cycle) {
  selection_flashes_ = 0;
  std::set<int> attended;
  std::optional<int> target;
  std::optional<int> retake_of;
  if (paradigm_.phase() == bci::Phase::CalibrationCue ||
      paradigm_.phase() == bci::Phase::CalibrationFlashing) {
    attended = e.codes;
    target = *e.codes.begin();
    if (e.retake) {
      retake_of = selection_;
      calibration_.retaken(selection_, objectOfCode(*target).id, reasons_.stopped_because, cycle,
                           s_);
    }
    s_.log.write("calibration_target", cycle.time_s, {{"object", objectOfCode(*target).id}});
  } else {
    attended = attendedCodes(e.objects_layout, cycle);
  }
  ++selection_;
  if (!target && e.objects_layout) {
    // An online object selection: its trial and what its codes stand for, for the post-hoc
    // decodings of learning from use.
    LearntSelection& learnt = learnt_[selection_];
    learnt.trial = paradigm_.trial();
    for (size_t slot : slots_) learnt.ids.push_back(settings_.world.objects[slot].id);
  }
  // The recording says where each selection starts and what it is, so an analysis splits the
  // flashes as the session did (bci/selection_marks.h).
  bci::MarkedSelection mark;
  mark.number = selection_;
  mark.kind = target ? bci::SelectionKind::Calibration
                     : (e.objects_layout ? bci::SelectionKind::Objects : bci::SelectionKind::Cells);
  mark.trial = target ? 0 : paradigm_.trial();
  mark.retake_of = retake_of;
  cycle.annotate(cycle.eeg_sample, bci::selectionMark(mark));
  selection_objects_ = e.objects_layout;
  truth_ = target ? std::set<int>{*target} : attended;
  cycle.record.paradigm.selection_started =
      SelectionStart{selection_,
                     e.objects_layout,
                     e.objects_layout ? paradigm_.objectLayout() : paradigm_.gridLayout(),
                     attended,
                     target,
                     retake_of,
                     mark.trial};
}

void ParadigmStage::onFlash(const bci::ParadigmEvent& e, Cycle& cycle) {
  if (!stimulus_.lit.count(e.code)) {
    // Its object's pose is stale: not shown, so not recorded as a flash either.
    const int object = objectOfCode(e.code).id;
    s_.log.write("flash_withheld", cycle.time_s,
                 {{"code", e.code}, {"object", object}, {"why", "tracking lost"}});
    view_watch_.flashWithheld(object, selection_, cycle, paradigm_, reasons_, s_);
    return;
  }
  view_watch_.flashShown();
  // Stamped when the frame that shows it is presented.
  cycle.record.paradigm.first_shown.push_back(
      {e.code, selection_objects_, truth_.count(e.code) > 0, !truth_.empty(), selection_});
  ++selection_flashes_;
}

void ParadigmStage::onSelectionMade(const bci::ParadigmEvent& e, Cycle& cycle) {
  const int number = paradigm_.trial();
  SelectionDecided decided;
  decided.objects = e.objects_layout;
  if (e.objects_layout) decided.object_id = objectOfCode(e.object).id;
  decided.cell = e.cell;
  decided.certainty = e.certainty;
  decided.flashes = selection_flashes_;
  decided.selection_s = cycle.record.presentation.selection_s;
  decided.selection_interrupted_s = cycle.record.presentation.selection_interrupted_s;
  const bool correct = trials_.recordSelection(number, decided);
  const TrialRecord& trial = trials_.at(number);
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
  // The evidence behind the certainty: each code's summed log-likelihood ratio and flashes, and
  // the score model it was weighed under.
  const P300Part& p300 = cycle.record.p300;
  nlohmann::json evidence = nlohmann::json::object();
  for (const auto& [code, value] : p300.decision.evidence) {
    const auto n = p300.decision.flashes.find(code);
    evidence[std::to_string(code)] = {
        {"llr", value}, {"flashes", n != p300.decision.flashes.end() ? n->second : 0}};
  }
  fields["evidence"] = evidence;
  fields["score_model"] = {
      {"separation", p300.scored_by.separation()},
      {"rho", p300.scored_by.rho},
      {"held_out_separation",
       p300.held_out_separation ? nlohmann::json(*p300.held_out_separation) : nlohmann::json()}};
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
  errp_.selectionMade(e.certainty);
}

void ParadigmStage::onFeedback(const bci::ParadigmEvent& e, Cycle& cycle) {
  FeedbackShown shown{e.codes, e.objects_layout, e.error};
  const bool online = !e.error.has_value();
  if (online) {
    const std::set<int> intended = intendedCodes(e.objects_layout);
    if (!intended.empty()) shown.error = e.codes != intended;
  }
  errp_.feedbackShown(online ? shown.error : std::nullopt);
  cycle.record.paradigm.feedback = shown;
}

void ParadigmStage::onErrpCorrection(const bci::ParadigmEvent& e, Cycle& cycle) {
  s_.log.write(
      "errp_correction", cycle.time_s,
      {{"trial", e.trial}, {"kind", e.objects_layout ? "object" : "cell"}, {"action", e.text}});
  errp_.corrected(e.text, cycle.time_s);
}

void ParadigmStage::onTrainModel(Cycle& cycle) {
  // On worker threads: the cycle (and the window) goes on; collectTraining() takes it.
  cycle.post(TrainRequest{settings_.classifier_method});
  calibration_.trainingStarted(cycle, s_);
}

void ParadigmStage::onRobotGrasp(const bci::ParadigmEvent& e, Cycle& cycle) {
  // The robot stage decides, and says on the record: it never grasps at a stale or unknown pose
  // (the experimenter retries once the cameras see the object), and a retried grasp whose object
  // is already in the gripper is done.
  const double time = cycle.time_s;
  const int id = objectOfCode(e.object).id;
  const auto& world = cycle.record.tracking.world;
  const auto seen = world ? world->object(id) : std::nullopt;
  GraspRequest grasp;
  grasp.object = id;
  if (seen) {
    grasp.at = seen->T_robot_object.translation;
    grasp.pose_age_s = seen->age(time);
  }
  grasp.max_pose_age_s = settings_.max_pose_age_s;
  grasp.retry = retrying_;
  grasp.time_s = time;
  cycle.post(grasp);
  const auto holding = cycle.record.robot.holding();
  const bool fresh = cycle.record.tracking.fresh(id, time);
  if (seen && (fresh || holding == id) && !(retrying_ && holding == id))
    trials_.at(paradigm_.trial()).robot_object = id;
}

void ParadigmStage::onRobotDrop(const bci::ParadigmEvent& e, Cycle& cycle) {
  const double time = cycle.time_s;
  if (retrying_ && !cycle.record.robot.holding()) {
    // Stopped after the object was let go: the arm goes home, and the put-down ends.
    cycle.post(FinishPutDownRequest{time});
    return;
  }
  TrialRecord& trial = trials_.at(paradigm_.trial());
  const auto other = objectOnCell(e.cell, cycle);
  if (other) {
    // Never onto another object: it goes back where it came from, and the trial says why.
    trial.outcome = "returned: cell " + std::to_string(e.cell.first) + "," +
                    std::to_string(e.cell.second) + " is taken by object " + std::to_string(*other);
    s_.tell.say(time, Severity::Warning,
                "trial " + std::to_string(trial.trial) + ": " + trial.outcome);
  }
  if (e.give_back) {
    trial.outcome = "returned: " + e.text;
    s_.tell.say(time, Severity::Warning,
                "trial " + std::to_string(trial.trial) + ": " + trial.outcome);
  }
  cycle.post(DropRequest{trial.trial, e.cell, other.has_value() || e.give_back, time});
  if (other || e.give_back)
    trial.robot_returned = true;
  else
    trial.robot_cell = e.cell;
}

void ParadigmStage::onTrialDone(const bci::ParadigmEvent& e, Cycle& cycle) {
  // An interruption the experimenter resumed by going on to the next trial ends here.
  if (TrialRecord* trial = trials_.find(e.trial);
      trial && !trial->interruptions.empty() && trial->interruptions.back().resumed_s < 0.0)
    trial->interruptions.back().resumed_s = cycle.time_s;
  trials_.done(e.trial, cycle.time_s, e.text);
  if (e.arm_held) trials_.at(e.trial).arm_held = true;
  s_.log.write("trial_done", cycle.time_s, {{"trial", e.trial}, {"text", e.text}});
  if (const TrialRecord* done = trials_.find(e.trial))
    s_.tell.say(cycle.time_s, Severity::Info, selectionLine(*done));
}

}  // namespace arbci::session
