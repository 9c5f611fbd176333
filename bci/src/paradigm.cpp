#include "arbci/bci/paradigm.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace arbci::bci {

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
      object_layout_(ParadigmLayout::single(std::max(objects, 2),
                                            settings.onsetFrames() / settings.display_hz)),
      grid_layout_(
          ParadigmLayout::matrix(rows, columns, settings.onsetFrames() / settings.display_hz)),
      random_(seed) {}

void Paradigm::event(ParadigmEvent e) {
  e.frame = now_;
  e.phase = phase_;
  e.trial = trial_;
  events_.push_back(std::move(e));
}

void Paradigm::enter(Phase phase, std::int64_t frame, const std::string& text) {
  phase_ = phase;
  now_ = std::max(now_, frame);
  ParadigmEvent e{ParadigmEvent::Kind::PhaseChanged};
  e.text = text.empty() ? toString(phase) : std::string(toString(phase)) + ": " + text;
  event(e);
}

void Paradigm::start(bool calibrate) {
  if (phase_ != Phase::Setup) return;
  calibrating_ = calibrate;
  if (calibrate && settings_.calibration_selections > 0) {
    calibration_target_ = std::uniform_int_distribution<int>(1, object_layout_.stimuli)(random_);
    phase_until_ =
        now_ + static_cast<std::int64_t>(std::lround(settings_.cue_s * settings_.display_hz));
    enter(Phase::CalibrationCue, now_, "object " + std::to_string(*calibration_target_));
    ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
    e.codes = {*calibration_target_};
    event(e);
  } else {
    calibrating_ = false;
    trial_ = 1;
    startFlashing(now_ + 1, true);
  }
}

void Paradigm::startFlashing(std::int64_t frame, bool objects) {
  flashing_objects_ = objects;
  const ParadigmLayout& layout = objects ? object_layout_ : grid_layout_;
  sequencer_.emplace(layout.codes(), random_());
  sequence_ = 0;
  stop_requested_ = false;
  awaiting_decision_ = false;
  if (objects) selected_cell_.reset();
  enter(calibrating_ ? Phase::CalibrationFlashing
                     : (objects ? Phase::ObjectFlashing : Phase::CellFlashing),
        frame);
  if (!calibrating_) {
    ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
    e.objects_layout = objects;
    event(e);
  }
  scheduleSequence(frame);
}

void Paradigm::scheduleSequence(std::int64_t first_frame) {
  schedule_.clear();
  next_flash_ = 0;
  ++sequence_;
  std::int64_t onset = first_frame;
  for (int code : sequencer_->next()) {
    schedule_.emplace_back(onset, code);
    onset += settings_.onsetFrames();
  }
}

FrameStimulus Paradigm::frame(std::int64_t index) {
  now_ = index;
  FrameStimulus out;
  const bool flashing = phase_ == Phase::CalibrationFlashing || phase_ == Phase::ObjectFlashing ||
                        phase_ == Phase::CellFlashing;
  if (flashing && !awaiting_decision_) {
    for (size_t i = 0; i < schedule_.size(); ++i) {
      const auto [onset, code] = schedule_[i];
      if (index == onset && i >= next_flash_) {
        ParadigmEvent e{ParadigmEvent::Kind::Flash};
        e.code = code;
        e.objects_layout = flashing_objects_;
        event(e);
        next_flash_ = i + 1;
      }
      if (index >= onset && index < onset + settings_.flashFrames()) out.lit.insert(code);
    }
    // The sequence's last interval is over: another sequence, or the end of flashing.
    if (!schedule_.empty() && index >= schedule_.back().first + settings_.onsetFrames() - 1) {
      const bool dynamic_stop =
          !calibrating_ && stop_requested_ && sequence_ >= settings_.min_sequences;
      const int most = calibrating_ ? settings_.calibration_sequences : settings_.sequences;
      if (sequence_ < most && !dynamic_stop) {
        scheduleSequence(index + 1);
      } else {
        awaiting_decision_ = true;
      }
    }
  }
  switch (phase_) {
    case Phase::CalibrationCue:
      if (index >= phase_until_) startFlashing(index + 1, true);
      break;
    case Phase::ObjectSelected:
      if (index >= phase_until_) {
        enter(Phase::Grasping, index, "object " + std::to_string(*selected_object_));
        ParadigmEvent e{ParadigmEvent::Kind::RobotGrasp};
        e.object = *selected_object_;
        event(e);
      }
      break;
    case Phase::CellSelected:
      if (index >= phase_until_) {
        enter(Phase::Dropping, index,
              "row " + std::to_string(selected_cell_->first) + " column " +
                  std::to_string(selected_cell_->second));
        ParadigmEvent e{ParadigmEvent::Kind::RobotDrop};
        e.cell = *selected_cell_;
        event(e);
      }
      break;
    default:
      break;
  }
  out.phase = phase_;
  out.grid_visible = phase_ == Phase::CellFlashing || phase_ == Phase::CellSelected ||
                     phase_ == Phase::Dropping || phase_ == Phase::Grasping;
  if (calibrating_ && (phase_ == Phase::CalibrationCue || phase_ == Phase::CalibrationFlashing))
    out.cued_object = calibration_target_;
  if (phase_ == Phase::ObjectSelected || phase_ == Phase::Grasping ||
      phase_ == Phase::CellFlashing || phase_ == Phase::CellSelected || phase_ == Phase::Dropping) {
    out.selected_object = selected_object_;
  }
  if (phase_ == Phase::CellSelected || phase_ == Phase::Dropping)
    out.selected_cell = selected_cell_;
  return out;
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
    if (calibration_done_ < settings_.calibration_selections) {
      calibration_target_ = std::uniform_int_distribution<int>(1, object_layout_.stimuli)(random_);
      phase_until_ = now_ + static_cast<std::int64_t>(std::lround(
                                (settings_.pause_s + settings_.cue_s) * settings_.display_hz));
      enter(Phase::CalibrationCue, now_, "object " + std::to_string(*calibration_target_));
      ParadigmEvent e{ParadigmEvent::Kind::SelectionStarted};
      e.codes = {*calibration_target_};
      event(e);
    } else {
      calibration_target_.reset();
      calibrating_ = false;
      enter(Phase::Training, now_);
      event(ParadigmEvent{ParadigmEvent::Kind::TrainModel});
    }
    return;
  }
  ParadigmEvent made{ParadigmEvent::Kind::SelectionMade};
  made.codes = decision.codes;
  made.certainty = decision.certainty;
  made.objects_layout = phase_ == Phase::ObjectFlashing;
  const std::int64_t show =
      static_cast<std::int64_t>(std::lround(settings_.result_s * settings_.display_hz));
  if (phase_ == Phase::ObjectFlashing) {
    selected_object_ = decision.choice + 1;
    made.object = *selected_object_;
    event(made);
    phase_until_ = now_ + show;
    enter(Phase::ObjectSelected, now_, "object " + std::to_string(*selected_object_));
  } else if (phase_ == Phase::CellFlashing) {
    selected_cell_ = {decision.choice / grid_layout_.columns + 1,
                      decision.choice % grid_layout_.columns + 1};
    made.cell = *selected_cell_;
    event(made);
    phase_until_ = now_ + show;
    enter(Phase::CellSelected, now_,
          "row " + std::to_string(selected_cell_->first) + " column " +
              std::to_string(selected_cell_->second));
  }
}

void Paradigm::modelTrained(bool ok, const std::string& text) {
  if (phase_ != Phase::Training) return;
  if (!ok) {
    enter(Phase::Aborted, now_, "training failed: " + text);
    return;
  }
  trial_ = 1;
  startFlashing(now_ + 1, true);
}

void Paradigm::robotFinished(bool success, const std::string& text) {
  if (phase_ != Phase::Grasping && phase_ != Phase::Dropping) return;
  if (!success) {
    paused_from_ = phase_;
    enter(Phase::RobotFault, now_, text);
    return;
  }
  if (phase_ == Phase::Grasping) {
    startFlashing(now_ + 1, false);
    return;
  }
  ParadigmEvent done{ParadigmEvent::Kind::TrialDone};
  event(done);
  selected_object_.reset();
  selected_cell_.reset();
  if (trial_ >= settings_.trials) {
    enter(Phase::Finished, now_);
  } else {
    ++trial_;
    startFlashing(
        now_ + static_cast<std::int64_t>(std::lround(settings_.pause_s * settings_.display_hz)),
        true);
  }
}

void Paradigm::setObjectCount(int objects) {
  if (objects >= 2) object_layout_ = ParadigmLayout::single(objects, object_layout_.soa_s);
}

void Paradigm::pause() {
  if (phase_ == Phase::Setup || phase_ == Phase::Finished || phase_ == Phase::Aborted ||
      phase_ == Phase::Paused || phase_ == Phase::EmergencyStop || phase_ == Phase::RobotFault) {
    return;
  }
  paused_from_ = phase_;
  phase_until_ -= now_;  // kept as the frames still to go
  enter(Phase::Paused, now_);
}

void Paradigm::resume() {
  if (phase_ == Phase::Paused) {
    const Phase back = paused_from_;
    phase_until_ += now_;
    enter(back, now_, "resumed");
    if ((back == Phase::CalibrationFlashing || back == Phase::ObjectFlashing ||
         back == Phase::CellFlashing) &&
        !awaiting_decision_) {
      // The interrupted sequence is shown again from its start.
      --sequence_;
      scheduleSequence(now_ + 1);
    }
    return;
  }
  if (phase_ == Phase::RobotFault || phase_ == Phase::EmergencyStop) {
    const Phase was = paused_from_;
    const bool robot_phase = was == Phase::Grasping || was == Phase::Dropping;
    if (!robot_phase && phase_ == Phase::EmergencyStop) {
      enter(was, now_, "resumed after the stop");
      if (was == Phase::CalibrationFlashing || was == Phase::ObjectFlashing ||
          was == Phase::CellFlashing) {
        --sequence_;
        scheduleSequence(now_ + 1);
      }
      return;
    }
    // The trial whose robot command failed is over; the next one starts.
    selected_object_.reset();
    selected_cell_.reset();
    if (trial_ >= settings_.trials) {
      enter(Phase::Finished, now_, "after a robot fault");
    } else {
      ++trial_;
      startFlashing(now_ + 1, true);
    }
  }
}

void Paradigm::abort() {
  if (phase_ == Phase::Finished || phase_ == Phase::Aborted) return;
  if (phase_ == Phase::Grasping || phase_ == Phase::Dropping)
    event(ParadigmEvent{ParadigmEvent::Kind::RobotStop});
  schedule_.clear();
  enter(Phase::Aborted, now_, "by the experimenter");
}

void Paradigm::emergencyStop() {
  if (phase_ == Phase::Finished || phase_ == Phase::Aborted) return;
  event(ParadigmEvent{ParadigmEvent::Kind::RobotStop});
  if (phase_ != Phase::EmergencyStop && phase_ != Phase::RobotFault && phase_ != Phase::Paused)
    paused_from_ = phase_;
  schedule_.clear();
  enter(Phase::EmergencyStop, now_);
}

std::vector<ParadigmEvent> Paradigm::takeEvents() {
  return std::exchange(events_, {});
}

}  // namespace arbci::bci
