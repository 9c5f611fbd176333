#include "arbci/bci/paradigm.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace arbci::bci {
namespace {
// Frame times are exact multiples of the frame period only on paper: a microsecond of slack.
constexpr double kSlack = 1e-6;

// The runner-up's probability once the first choice is rejected: its share of what that choice
// left (0 when it left nothing).
double runnerUpCertainty(const Decision& d) {
  const double rest = 1.0 - d.certainty;
  return rest > 0.0 ? d.runner_up_certainty / rest : 0.0;
}
}  // namespace

int ParadigmSettings::flashFrames() const {
  return std::max(1, static_cast<int>(std::lround(flash_ms * display_hz / 1000.0)));
}

int ParadigmSettings::onsetFrames() const {
  return std::max(flashFrames() + 1,
                  static_cast<int>(std::lround((flash_ms + isi_ms) * display_hz / 1000.0)));
}

const char* toString(Phase phase) {
  switch (phase) {
    case Phase::Setup:
      return "set-up";
    case Phase::CalibrationCue:
      return "calibration: target cued";
    case Phase::CalibrationFlashing:
      return "calibration: flashing";
    case Phase::CalibrationFeedback:
      return "calibration: feedback";
    case Phase::Training:
      return "training the classifier";
    case Phase::ObjectFlashing:
      return "phase 1: objects flashing";
    case Phase::ObjectSelected:
      return "phase 1: object selected";
    case Phase::Grasping:
      return "robot grasping";
    case Phase::CellFlashing:
      return "phase 2: grid flashing";
    case Phase::CellSelected:
      return "phase 2: cell selected";
    case Phase::Dropping:
      return "robot putting down";
    case Phase::Finished:
      return "finished";
    case Phase::Aborted:
      return "aborted";
    case Phase::Paused:
      return "paused";
    case Phase::EmergencyStop:
      return "EMERGENCY STOP";
    case Phase::RobotFault:
      return "robot fault: waiting for the experimenter";
  }
  return "unknown";
}

Paradigm::Paradigm(const ParadigmSettings& settings, int objects, int rows, int columns,
                   std::uint64_t seed)
    : settings_(settings),
      object_layout_(ParadigmLayout::single(std::max(objects, 2), settings.soaSeconds())),
      grid_layout_(ParadigmLayout::matrix(rows, columns, settings.soaSeconds())),
      random_(seed) {}

void Paradigm::event(ParadigmEvent e) {
  e.frame = frame_;
  e.phase = phase_;
  e.trial = trial_;
  events_.push_back(std::move(e));
}

void Paradigm::enter(Phase phase, const std::string& text) {
  phase_ = phase;
  ParadigmEvent e{ParadigmEvent::Kind::PhaseChanged};
  e.text = text.empty() ? toString(phase) : std::string(toString(phase)) + ": " + text;
  event(e);
}

void Paradigm::start(bool calibrate) {
  if (phase_ != Phase::Setup) return;
  calibrating_ = calibrate || settings_.flashes_only;
  if (calibrating_ && settings_.calibration_selections > 0) {
    cueCalibrationTarget(0.0);
  } else {
    calibrating_ = false;
    trial_ = 1;
    startFlashing(nextFrame(), true);
  }
}

void Paradigm::cueCalibrationTarget(double delay_s) {
  calibration_target_ = *object_layout_.drawTarget(random_).begin();
  phase_until_ = now_ + delay_s + settings_.cue_s;
  enter(Phase::CalibrationCue, objectName(*calibration_target_));
  ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
  e.codes = {*calibration_target_};
  event(e);
}

void Paradigm::startFlashing(double at_s, bool objects) {
  flashing_objects_ = objects;
  const ParadigmLayout& layout = objects ? object_layout_ : grid_layout_;
  sequencer_.emplace(layout.codes(), random_());
  sequence_ = 0;
  stop_requested_ = false;
  awaiting_decision_ = false;
  sequences_override_ = 0;
  corrections_ = 0;
  verdict_pending_ = false;
  giving_back_ = false;
  if (objects) selected_cell_.reset();
  enter(calibrating_ ? Phase::CalibrationFlashing
                     : (objects ? Phase::ObjectFlashing : Phase::CellFlashing));
  if (!calibrating_) {
    ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
    e.objects_layout = objects;
    event(e);
  }
  scheduleSequence(at_s);
}

void Paradigm::scheduleSequence(double first_onset_s) {
  schedule_.clear();
  next_flash_ = 0;
  ++sequence_;
  double onset = first_onset_s;
  for (int code : sequencer_->next()) {
    schedule_.push_back({onset, code});
    onset += settings_.soaSeconds();
  }
}

FrameStimulus Paradigm::frame(std::int64_t index, double due_s) {
  frame_ = index;
  now_ = due_s;
  FrameStimulus out;
  const bool flashing = phase_ == Phase::CalibrationFlashing || phase_ == Phase::ObjectFlashing ||
                        phase_ == Phase::CellFlashing;
  if (flashing && !awaiting_decision_) endSequenceIfOver(due_s);
  if (flashing && !awaiting_decision_) showFlashes(due_s, out);
  advanceTimedPhase(due_s);
  describe(out);
  if (lit_last_frame_ && out.lit.empty()) {
    last_dark_s_ = due_s;
    dark_frame_ = index;
  }
  lit_last_frame_ = !out.lit.empty();
  return out;
}

void Paradigm::endSequenceIfOver(double due_s) {
  // The sequence's last interval is over (and its every flash shown): another sequence, or the
  // end of flashing.
  if (schedule_.empty() || next_flash_ != schedule_.size() ||
      due_s < schedule_.back().onset_s + settings_.soaSeconds() - kSlack)
    return;
  // A selection repeated after an ErrP rejection shows all its sequences.
  const bool dynamic_stop = !calibrating_ && sequences_override_ == 0 && stop_requested_ &&
                            sequence_ >= settings_.min_sequences;
  // A cell held to the objects' certainty (learning from use, trusted) gets the objects' room to
  // reach it.
  const bool cell_as_object =
      hold_uncertain_cells_ && object_sequences_ == ObjectSequences::Trusted;
  const int most = calibrating_              ? settings_.calibration_sequences
                   : sequences_override_ > 0 ? sequences_override_
                   : phase_ == Phase::ObjectFlashing || cell_as_object ? objectSequences()
                                                                       : settings_.sequences;
  if (sequence_ < most && !dynamic_stop) {
    scheduleSequence(schedule_.back().onset_s + settings_.soaSeconds());
  } else {
    awaiting_decision_ = true;
  }
}

void Paradigm::showFlashes(double due_s, FrameStimulus& out) {
  for (size_t i = 0; i < schedule_.size(); ++i) {
    ScheduledFlash& f = schedule_[i];
    if (due_s < f.onset_s - kSlack) break;
    if (i == next_flash_) {
      if (showNextFlash(i, due_s)) out.lit.insert(f.code);
      break;
    }
    if (i < next_flash_ && due_s < f.shown_s + settings_.flashSeconds() - kSlack)
      out.lit.insert(f.code);
  }
}

bool Paradigm::showNextFlash(size_t i, double due_s) {
  ScheduledFlash& f = schedule_[i];
  // Never on the frame right after one that showed a flash: on a display too slow for the SOA
  // the two would run together (one onset to the subject, one photodiode edge); it waits a
  // frame, with the screen dark between them.
  if (lit_last_frame_) return false;
  // Never closer than the SOA to the previous onset, nor than the dark gap (SOA less the flash, in
  // whole frames) to the frame that ended it: after late frames the schedule slips (the selection
  // takes longer) rather than squeezing flashes together.
  const double soa = settings_.soaSeconds();
  const double ready = std::max(last_onset_s_ + soa, last_dark_s_ + soa - settings_.flashSeconds());
  if (due_s < ready - kSlack) return false;
  // Its first frame. One overdue by more than a flash (the process or the display stalled) moves
  // the rest of the sequence with it: shown one per frame, the flashes missed in a stall would
  // follow each other closer than the SOA, their ERPs overlapping and the photodiode patch never
  // going dark between them.
  if (due_s > f.onset_s + settings_.flashSeconds()) {
    const double late = due_s - f.onset_s;
    for (size_t j = i; j < schedule_.size(); ++j) schedule_[j].onset_s += late;
  }
  ParadigmEvent e{ParadigmEvent::Kind::Flash};
  e.code = f.code;
  e.objects_layout = flashing_objects_;
  event(e);
  f.shown_s = due_s;
  last_onset_s_ = due_s;
  onset_frame_ = frame_;
  next_flash_ = i + 1;
  return true;
}

void Paradigm::advanceTimedPhase(double due_s) {
  if (due_s < phase_until_ - kSlack) return;
  switch (phase_) {
    case Phase::CalibrationCue:
      if (errp_block_) {
        showCalibrationFeedback(due_s);
      } else {
        startFlashing(nextFrame(), true);
      }
      break;
    case Phase::CalibrationFeedback:
      selected_object_.reset();
      if (++errp_done_ < errp_plan_.size()) {
        cueCalibrationTarget(settings_.pause_s);
      } else {
        errp_block_ = false;
        endCalibration();
      }
      break;
    case Phase::ObjectSelected:
    case Phase::CellSelected:
      if (runner_up_waiting_) {
        runner_up_waiting_ = false;
        const Decision& d = last_decision_;
        showSelection(d.runner_up_codes, d.runner_up_choice, runnerUpCertainty(d),
                      phase_ == Phase::ObjectSelected, "runner-up");
      } else if (!verdict_pending_ && phase_ == Phase::ObjectSelected && held_now_) {
        if (held_fit_pending_) break;  // shown until the fit with it in comes back
        held_now_ = false;
        if (held_act_) {
          held_act_ = false;
          askRobot(Phase::Grasping);
        } else {
          nextTrial(now_ + settings_.pause_s, held_why_, true);
        }
      } else if (!verdict_pending_ && phase_ == Phase::ObjectSelected && unsure()) {
        // A selection that ran out of sequences below what the arm acts on is an "I don't
        // know": said and recorded, and its trial ends without the arm.
        char why[200];
        std::snprintf(why, sizeof why,
                      "not grasped: the object was chosen at a certainty of %.4f, below "
                      "paradigm.%s %g",
                      shown_certainty_, actThresholdName(), actThreshold());
        nextTrial(now_ + settings_.pause_s, why, true);
      } else if (!verdict_pending_ && phase_ == Phase::CellSelected && unsure()) {
        char why[200];
        std::snprintf(why, sizeof why,
                      "the cell was chosen at a certainty of %.4f, below paradigm.%s %g",
                      shown_certainty_, actThresholdName(), actThreshold());
        giving_back_ = true;
        give_back_why_ = why;
        askRobot(Phase::Dropping);
      } else if (!verdict_pending_) {
        askRobot(phase_ == Phase::ObjectSelected ? Phase::Grasping : Phase::Dropping);
      }
      break;
    default:
      break;
  }
}

double Paradigm::actThreshold() const {
  return hold_uncertain_cells_ ? settings_.certainty : settings_.act_certainty;
}

const char* Paradigm::actThresholdName() const {
  return hold_uncertain_cells_ ? "certainty" : "act_certainty";
}

bool Paradigm::unsure() const {
  // An ErrP correction is the runner-up the rejection left: its own rule (errp_runner_up) decided.
  return actThreshold() > 0.0 && !shown_correction_ && shown_certainty_ < actThreshold();
}

void Paradigm::showCalibrationFeedback(double due_s) {
  // The ErrP block: the cued object, or deliberately another, shown as if selected.
  int shown = *calibration_target_;
  const bool wrong = errp_plan_[errp_done_];
  if (wrong) {
    std::uniform_int_distribution<int> other(1, object_layout_.stimuli - 1);
    shown = other(random_);
    if (shown >= *calibration_target_) ++shown;
  }
  shown_codes_ = {shown};
  shown_error_ = wrong;
  selected_object_ = shown;
  feedback_pending_ = true;
  phase_until_ = due_s + settings_.result_s;
  enter(Phase::CalibrationFeedback, objectName(shown) + (wrong ? " (wrong)" : ""));
}

void Paradigm::endCalibration() {
  calibration_target_.reset();
  calibrating_ = false;
  enter(Phase::Training);
  event(ParadigmEvent{ParadigmEvent::Kind::TrainModel});
}

void Paradigm::describe(FrameStimulus& out) {
  out.phase = phase_;
  out.grid_visible = phase_ == Phase::CellFlashing || phase_ == Phase::CellSelected ||
                     phase_ == Phase::Dropping || phase_ == Phase::Grasping;
  if (calibrating_ && (phase_ == Phase::CalibrationCue || phase_ == Phase::CalibrationFlashing))
    out.cued_object = calibration_target_;
  if (phase_ == Phase::CalibrationFeedback) out.selected_object = selected_object_;
  // The first frame that shows a selection: its feedback's onset (stamped when presented).
  if (feedback_pending_ && (phase_ == Phase::ObjectSelected || phase_ == Phase::CellSelected ||
                            phase_ == Phase::CalibrationFeedback)) {
    feedback_pending_ = false;
    ParadigmEvent e{ParadigmEvent::Kind::Feedback};
    e.codes = shown_codes_;
    e.objects_layout = phase_ != Phase::CellSelected;
    e.error = phase_ == Phase::CalibrationFeedback ? shown_error_ : std::nullopt;
    event(e);
  }
  if (phase_ == Phase::ObjectSelected || phase_ == Phase::Grasping ||
      phase_ == Phase::CellFlashing || phase_ == Phase::CellSelected || phase_ == Phase::Dropping) {
    out.selected_object = selected_object_;
  }
  if (phase_ == Phase::CellSelected || phase_ == Phase::Dropping)
    out.selected_cell = selected_cell_;
}

void Paradigm::presented(std::int64_t index, double at_s) {
  // A frame shown later than it was due moves what the next flash must keep its distance from:
  // the gap and the SOA the screen really showed, not those the schedule planned.
  if (index == onset_frame_) last_onset_s_ = std::max(last_onset_s_, at_s);
  if (index == dark_frame_) last_dark_s_ = std::max(last_dark_s_, at_s);
}

void Paradigm::askRobot(Phase phase) {
  if (phase == Phase::Grasping) {
    enter(Phase::Grasping, objectName(*selected_object_));
    ParadigmEvent e{ParadigmEvent::Kind::RobotGrasp};
    e.object = *selected_object_;
    event(e);
    return;
  }
  enter(Phase::Dropping, "row " + std::to_string(selected_cell_->first) + " column " +
                             std::to_string(selected_cell_->second));
  ParadigmEvent e{ParadigmEvent::Kind::RobotDrop};
  e.cell = *selected_cell_;
  e.give_back = giving_back_;
  if (giving_back_) e.text = give_back_why_;
  event(e);
}

void Paradigm::requestStopFlashing() {
  stop_requested_ = true;
}

void Paradigm::decide(const Decision& decision) {
  if (!awaiting_decision_) return;
  awaiting_decision_ = false;
  schedule_.clear();
  if (phase_ == Phase::CalibrationFlashing) {
    ++calibration_done_;
    if (settings_.flashes_only || calibration_done_ < settings_.calibration_selections) {
      cueCalibrationTarget(settings_.pause_s);
    } else if (settings_.errp && settings_.errp_calibration_feedbacks > 0) {
      // The ErrP block: a fixed share of wrong feedbacks, in random order.
      const int n = settings_.errp_calibration_feedbacks;
      const int wrong = static_cast<int>(std::lround(settings_.errp_wrong_rate * n));
      errp_plan_.assign(static_cast<size_t>(n), false);
      std::fill(errp_plan_.begin(), errp_plan_.begin() + wrong, true);
      std::shuffle(errp_plan_.begin(), errp_plan_.end(), random_);
      errp_done_ = 0;
      errp_block_ = true;
      cueCalibrationTarget(settings_.pause_s);
    } else {
      endCalibration();
    }
    return;
  }
  if (phase_ != Phase::ObjectFlashing && phase_ != Phase::CellFlashing) return;
  if (decision.choice < 0) {
    // No model to decide with yet (learning from use, before its first fit).
    nextTrial(now_ + settings_.pause_s, hold_why_.empty() ? "no model to decide with" : hold_why_,
              hold_arm_);
    return;
  }
  last_decision_ = decision;
  runner_up_taken_ = false;
  runner_up_waiting_ = false;
  showSelection(decision.codes, decision.choice, decision.certainty,
                phase_ == Phase::ObjectFlashing, "");
}

void Paradigm::showSelection(const std::set<int>& codes, int choice, double certainty, bool objects,
                             const std::string& text) {
  ParadigmEvent made{ParadigmEvent::Kind::SelectionMade};
  made.codes = codes;
  made.certainty = certainty;
  made.objects_layout = objects;
  made.text = text;
  shown_codes_ = codes;
  shown_certainty_ = certainty;
  shown_correction_ = text == "runner-up";
  shown_error_.reset();
  feedback_pending_ = true;
  verdict_pending_ = settings_.errp;
  phase_until_ = now_ + settings_.result_s;
  if (objects) {
    held_now_ = hold_arm_;
    held_why_ = hold_why_;
    held_fit_pending_ = held_act_ = false;
    selected_object_ = choice + 1;
    made.object = *selected_object_;
    event(made);
    enter(Phase::ObjectSelected,
          objectName(*selected_object_) + (text.empty() ? "" : " (" + text + ")"));
  } else {
    selected_cell_ = {choice / grid_layout_.columns + 1, choice % grid_layout_.columns + 1};
    made.cell = *selected_cell_;
    event(made);
    enter(Phase::CellSelected, "row " + std::to_string(selected_cell_->first) + " column " +
                                   std::to_string(selected_cell_->second) +
                                   (text.empty() ? "" : " (" + text + ")"));
  }
}

bool Paradigm::awaitingErrpVerdict() const {
  return verdict_pending_ && (phase_ == Phase::ObjectSelected || phase_ == Phase::CellSelected);
}

void Paradigm::errpVerdict(bool error) {
  if (!awaitingErrpVerdict()) return;
  verdict_pending_ = false;
  if (!error) return;  // executed once the selection has been shown its time
  const bool objects = phase_ == Phase::ObjectSelected;
  ++corrections_;
  ParadigmEvent correction{ParadigmEvent::Kind::ErrpCorrection};
  correction.objects_layout = objects;
  if (corrections_ > settings_.errp_max_corrections) {
    const std::string why =
        "the ErrP rejected " + std::to_string(corrections_) + " selections in a row";
    if (objects) {
      correction.text = "skip";
      event(correction);
      nextTrial(nextFrame(), "skipped: " + why);
    } else {
      // The arm holds the object: never left in the gripper, it goes back where it was taken.
      correction.text = "return";
      event(correction);
      giving_back_ = true;
      give_back_why_ = "the ErrP rejected every cell selected";
      askRobot(Phase::Dropping);
    }
    return;
  }
  const Decision& d = last_decision_;
  if (!runner_up_taken_ && d.runner_up_choice >= 0 &&
      runnerUpCertainty(d) >= settings_.errp_runner_up) {
    runner_up_taken_ = true;
    correction.text = "runner-up";
    event(correction);
    // The rejected choice is cleared at once; the runner-up is shown after a pause (frame()),
    // its feedback clear of the last one's ErrP.
    runner_up_waiting_ = true;
    if (objects) {
      selected_object_.reset();
    } else {
      selected_cell_.reset();
    }
    phase_until_ = now_ + settings_.pause_s;
    return;
  }
  correction.text = "repeat";
  event(correction);
  const int corrections = corrections_;
  startFlashing(nextFrame(), objects);
  corrections_ = corrections;
  sequences_override_ = settings_.errp_repeat_sequences > 0 ? settings_.errp_repeat_sequences
                                                            : 2 * settings_.sequences;
}

void Paradigm::modelTrained(bool ok, const std::string& text) {
  if (phase_ != Phase::Training) return;
  if (!ok) {
    enter(Phase::Aborted, "training failed: " + text);
    return;
  }
  trial_ = 1;
  // The pause between selections, as between trials: the subject sees the calibration is over
  // before the first free choice flashes (and the recording shows a gap between them).
  startFlashing(now_ + settings_.pause_s, true);
}

void Paradigm::holdArm(bool held, const std::string& why) {
  hold_arm_ = held;
  hold_why_ = why;
}

void Paradigm::setObjectSequences(ObjectSequences mode) {
  object_sequences_ = mode;
}

int Paradigm::objectSequences() const {
  switch (object_sequences_) {
    case ObjectSequences::Learning:
      return settings_.untrustedSequences();
    case ObjectSequences::Trusted:
      return settings_.trustedMaxSequences();
    case ObjectSequences::Usual:
      break;
  }
  return settings_.sequences;
}

void Paradigm::judgeHeldSelection(bool pending, bool act, const std::string& why) {
  held_fit_pending_ = pending;
  held_act_ = act;
  held_why_ = why;
}

void Paradigm::recalibrate() {
  if (phase_ != Phase::Training) return;
  calibration_done_ = 0;
  errp_block_ = false;
  errp_done_ = 0;
  errp_plan_.clear();
  calibrating_ = true;
  cueCalibrationTarget(settings_.pause_s);
}

void Paradigm::robotFinished(bool success, const std::string& text) {
  if (phase_ != Phase::Grasping && phase_ != Phase::Dropping) return;
  if (!success) {
    paused_from_ = phase_;
    enter(Phase::RobotFault, text);
    return;
  }
  if (phase_ == Phase::Grasping) {
    startFlashing(nextFrame(), false);
    return;
  }
  nextTrial(now_ + settings_.pause_s, "");
}

void Paradigm::nextTrial(double at_s, const std::string& why, bool arm_held) {
  ParadigmEvent done{ParadigmEvent::Kind::TrialDone};
  done.text = why;
  done.arm_held = arm_held;
  event(done);
  selected_object_.reset();
  selected_cell_.reset();
  if (trial_ >= settings_.trials) {
    enter(Phase::Finished, why);
  } else {
    ++trial_;
    startFlashing(at_s, true);
  }
}

void Paradigm::setObjectCount(int objects) {
  if (objects >= 2) object_layout_ = ParadigmLayout::single(objects, object_layout_.soa_s);
}

void Paradigm::setObjectNames(std::vector<int> ids) {
  object_ids_ = std::move(ids);
}

std::string Paradigm::objectName(int slot) const {
  const bool named = slot >= 1 && slot <= static_cast<int>(object_ids_.size());
  return "object " + std::to_string(named ? object_ids_[static_cast<size_t>(slot - 1)] : slot);
}

void Paradigm::pause() {
  if (phase_ == Phase::Setup || phase_ == Phase::Finished || phase_ == Phase::Aborted ||
      phase_ == Phase::Paused || phase_ == Phase::EmergencyStop || phase_ == Phase::RobotFault) {
    return;
  }
  paused_from_ = phase_;
  phase_until_ -= now_;  // kept as the time still to go
  enter(Phase::Paused);
}

void Paradigm::restartSequence() {
  if (awaiting_decision_) return;
  if (next_flash_ > 0) ++reflashed_sequences_;
  --sequence_;
  scheduleSequence(nextFrame());
}

void Paradigm::returnToFlashing(Phase phase, bool retake) {
  if (phase == Phase::CalibrationFlashing && !awaiting_decision_ && retake) {
    retakeCalibrationSelection();
  } else if (phase == Phase::CalibrationFlashing || phase == Phase::ObjectFlashing ||
             phase == Phase::CellFlashing) {
    restartSequence();
  }
}

void Paradigm::retakeCalibrationSelection() {
  // Training needs whole selections: flashes on both sides of a pause (or with some withheld)
  // would be split into pieces at the gap. The same target is cued again and flashed from the
  // first sequence; the session leaves the interrupted flashes out of training.
  schedule_.clear();
  next_flash_ = 0;
  sequence_ = 0;
  ++calibration_retakes_;
  phase_until_ = now_ + settings_.cue_s;
  enter(Phase::CalibrationCue,
        objectName(*calibration_target_) + " again (the selection was interrupted)");
  ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
  e.codes = {*calibration_target_};
  e.retake = true;
  event(e);
}

std::optional<Phase> Paradigm::interrupted() const {
  if (phase_ != Phase::EmergencyStop && phase_ != Phase::RobotFault) return std::nullopt;
  return paused_from_;
}

void Paradigm::resume(bool retake) {
  if (phase_ == Phase::Paused) {
    const Phase back = paused_from_;
    phase_until_ += now_;
    if (back != Phase::CalibrationFlashing || awaiting_decision_ || !retake) enter(back, "resumed");
    returnToFlashing(back, retake);
    return;
  }
  const auto was = interrupted();
  if (!was) return;
  if (*was == Phase::Grasping || *was == Phase::Dropping) {
    // The trial whose robot step was interrupted is over; the next one starts.
    nextTrial(nextFrame(), "after " + std::string(toString(phase_)));
    return;
  }
  retryStep();
}

void Paradigm::resumeHeld() {
  if (phase_ != Phase::Paused) return;
  const Phase back = paused_from_;
  phase_until_ += now_;
  enter(back, "resumed after a stall");
  if (back == Phase::CalibrationFlashing || back == Phase::ObjectFlashing ||
      back == Phase::CellFlashing)
    restartSequence();
}

void Paradigm::retryStep() {
  const auto was = interrupted();
  if (!was) return;
  if (*was == Phase::Grasping || *was == Phase::Dropping) {
    askRobot(*was);
    return;
  }
  enter(*was, std::string("resumed after the ") +
                  (phase_ == Phase::EmergencyStop ? "emergency stop" : "robot fault"));
  returnToFlashing(*was, false);
  // A timed phase (cue, selection shown) starts its time again.
  if (*was == Phase::CalibrationCue) phase_until_ = now_ + settings_.cue_s;
  if (*was == Phase::ObjectSelected || *was == Phase::CellSelected)
    phase_until_ = now_ + settings_.result_s;
}

void Paradigm::skipTrial(const std::string& why) {
  if (!interrupted() || trial_ < 1) return;
  nextTrial(nextFrame(),
            why.empty() ? "trial " + std::to_string(trial_) + " skipped by the experimenter" : why);
}

void Paradigm::abort() {
  if (phase_ == Phase::Finished || phase_ == Phase::Aborted) return;
  if (phase_ == Phase::Grasping || phase_ == Phase::Dropping)
    event(ParadigmEvent{ParadigmEvent::Kind::RobotStop});
  schedule_.clear();
  enter(Phase::Aborted, "by the experimenter");
}

void Paradigm::emergencyStop() {
  if (phase_ == Phase::Finished || phase_ == Phase::Aborted) return;
  event(ParadigmEvent{ParadigmEvent::Kind::RobotStop});
  if (phase_ != Phase::EmergencyStop && phase_ != Phase::RobotFault && phase_ != Phase::Paused)
    paused_from_ = phase_;
  schedule_.clear();
  enter(Phase::EmergencyStop);
}

std::vector<ParadigmEvent> Paradigm::takeEvents() {
  return std::exchange(events_, {});
}

}  // namespace arbci::bci
