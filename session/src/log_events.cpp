#include "arbci/session/log_events.h"

#include <sstream>

namespace arbci::session {
namespace {

// By name. A new event is added here with its fields and meaning, and docs/log.md printed again
// (`arbci log-events`); tests/session/log_events_test.cpp holds the sources to this table.
constexpr LogEvent kEvents[] = {
    {"calibration_retake", "selection, object, reason, retaken_as",
     "A calibration selection interrupted (a pause, a fault) and cued again as a new one; its "
     "flashes are left out of training."},
    {"calibration_review", "auc, min_auc, decision, below",
     "The experimenter's answer to the calibration review (go online or recalibrate), with the "
     "model's AUC against gates.min_auc."},
    {"calibration_target", "object",
     "The calibration run cued the object (marker id) the subject attends next."},
    {"cycle", "frame, compute_ms, stages",
     "Every sixth frame: the cycle's compute time and each stage's (ms)."},
    {"display_too_slow", "configured_hz, median_frame_ms, text",
     "The display presents frames more slowly than display_hz: flashes are stamped as presented, "
     "the SOA is longer than configured."},
    {"eeg_clock", "warning",
     "The EEG clock runs further off the source's rate than the clock fit allows: flash stamps are "
     "uncertain (check eeg.rate_hz against the amplifier)."},
    {"eeg_source", "fault, state",
     "The live EEG source stopped delivering, or came back (its fault in words)."},
    {"eeg_stall", "first_sample, samples, seconds_of_signal, held_s, late_s, uncertain_flashes",
     "A delivery of EEG held up: where and for how long, and the flash stamps it made uncertain."},
    {"emergency_stop", "by", "An emergency stop, and who pressed it."},
    {"epoch_discarded", "sample, code, reason",
     "A flash's epoch not scored (an artefact, a gap in the signal)."},
    {"errp_correction", "trial, kind, action",
     "The ErrP verdict changed what the trial does next (object or cell; the action in words)."},
    {"errp_decision",
     "trial, kind, object, cell, correct, veto, why, score, prior_error, posterior_error, "
     "threshold",
     "The error-potential classifier's verdict on a selection's feedback."},
    {"errp_trained", "auc, auc_95, error_feedbacks, correct_feedbacks",
     "The ErrP classifier trained, with its cross-validated AUC and interval."},
    {"errp_training_failed", "reason",
     "The ErrP classifier could not be trained (the trials go on without it)."},
    {"flash_withheld", "code, object, why",
     "A flash not shown because its object's pose was stale (so not recorded as a flash either)."},
    {"grasp_view", "object, seconds, pose_age_max_s, never_seen",
     "How fresh the grasped object's pose stayed while the arm came down."},
    {"hmd_frame", "frame, display_s, submitted_s, lead_ms, head",
     "hmd.output openxr: each frame's predicted display time (its flashes' stamp), when it was "
     "handed to the runtime, and the headset's pose (x, y, z, qx, qy, qz, qw; LOCAL space)."},
    {"intended_not_in_view", "trial, object",
     "The trial's intended object is not in view: the trial waits for it."},
    {"late_frame", "frame, due_s, late_ms, stages",
     "A frame presented later than it was due, with the stages' times."},
    {"learning_fit",
     "fit, selections, agreeing, restarts, consistency, explained, shuffled_explained, "
     "beats_shuffled, p3_uv, separation_fitted, separation_held_out, post_hoc, changed, trusted, "
     "waiting_for",
     "Learning from use: a fit over the object selections so far, its checks and whether the arm "
     "may act on it."},
    {"learning_fit_failed", "reason",
     "Learning from use: a fit failed (the model before it is kept)."},
    {"lost_samples", "total, new",
     "EEG samples lost (counted from the source's numbering or the clock)."},
    {"lsl_markers", "stream, port, scope",
     "The LSL Markers stream opened (its name, port and scope)."},
    {"model", "method, provenance",
     "The P300 model in use (trained now, or read from a file) and where it came from."},
    {"model_refused", "reason", "A model file refused (another montage, rate or kind) and why."},
    {"model_warning", "text",
     "A warning about the model in use (e.g. trained on another session's setup)."},
    {"note", "text, sample",
     "A note for the recording (the experimenter's, or the session's), at its sample."},
    {"objects_in_view", "objects, kept",
     "The objects in view when a trial's object flashing began (kept: why fewer than all flash)."},
    {"overrun", "frame, compute_ms, stages",
     "A cycle whose compute time exceeded the EEG block's."},
    {"paused", "reason, fault",
     "The run paused, and why (the experimenter, or a stage's reason; a fault)."},
    {"pc_too_slow", "stalls, window_s, longest_s",
     "The PC stalled too often (stalls in the last window_s, the longest): the experimenter is "
     "asked to pause; headless, it is said and the run goes on."},
    {"phase", "phase, text, trial",
     "The paradigm entered a phase (with its words: a fault, a failed training)."},
    {"placement",
     "trial, object, position, seen_at, error_m, why, robot_reported, robot_vs_cameras_m",
     "Where a put-down object was seen by the cameras, against where it was meant to go."},
    {"placement_reported", "trial, object, position",
     "Where the robot reported a put-down object."},
    {"preflight", "passed, camera_frames, eeg_rate_hz, failures, questioned",
     "The pre-flight check's verdict, what it measured and what failed or was questioned."},
    {"preflight_started", "", "The pre-flight check began (Start pressed)."},
    {"recording_failed", "text, samples",
     "The recording could not be written (a full disk): samples lost until it can."},
    {"recovery", "action, trial, why",
     "The experimenter's recovery step (retry, skip, end) after a robot fault."},
    {"reference", "id, position", "The reference marker's id and position in the robot frame."},
    {"refused", "action, why", "An experimenter's action refused, and why."},
    {"resumed", "reason", "The run resumed after a pause."},
    {"retakes_capped", "reason",
     "Calibration retakes reached their cap: the calibration goes on without more."},
    {"robot", "kind, sequence, command, text, reason, outcome, may_have_run, heartbeat_priority",
     "The robot backend's answer or event (a reply, a fault, a heartbeat)."},
    {"robot_clock_lost", "text",
     "A stepped robot backend (a headless run's simulated arm) stopped answering its clock steps."},
    {"robot_command", "command, object, target, sequence, cell, returning, by, after",
     "A command sent to the robot backend."},
    {"robot_refused", "command, object, why",
     "A robot command not sent (an unknown or stale pose, a busy arm) and why."},
    {"robot_step_done", "step, object", "A trial's robot step finished."},
    {"robot_stopped_at_end", "reason", "A motion still in flight STOPped when the session ended."},
    {"screenshot_failed", "text", "An HMD screenshot could not be written (the run goes on)."},
    {"selection",
     "trial, kind, certainty, flashes, correct, selected, intended, llr, evidence, score_model, "
     "separation, rho, held_out_separation",
     "A selection decided: what was chosen, its certainty and the evidence behind it per code."},
    {"session_ended", "reason", "The session ended, and why."},
    {"session_started", "folder, session, seed",
     "The session started: its folder, session file and seed."},
    {"signal_quality", "verdict, gate, bad_channels, channels",
     "The EEG quality gate's verdict at Start, channel by channel."},
    {"stall", "what, held",
     "Every marker vanished at once (the machine stalled, not the tracking): the flashes are held "
     "until the markers are back."},
    {"stall_ended", "seconds", "A stall ended after this many seconds."},
    {"summary_not_written", "text", "summary.json could not be written (why)."},
    {"timing_limit", "text, paused",
     "The timing gate's limit reached: the run pauses (or goes on, annotated)."},
    {"timing_off_limits", "what, ms, limit_ms, onset_sample, selection",
     "A flash or gap outside the paradigm's timing limits."},
    {"timing_policy", "policy, why",
     "The timing gate's policy for the rest of the run (pause, annotate), and why."},
    {"trained",
     "method, training_s, frames_while_training, longest_frame_ms, median_frame_ms, auc, "
     "accuracy_by_sequences, selections_used, selections_left_out",
     "The P300 classifier trained on the calibration run, with its cross-validation."},
    {"training_failed", "reason",
     "Training failed (the run is aborted, or waits for a recalibration)."},
    {"training_started", "method", "Training of the P300 classifier started."},
    {"trial_done", "trial, text", "A trial ended, with its line (as the Session panel shows it)."},
    {"trigger", "frame, byte, what, swap_s, written_s, latency_ms",
     "eeg.trigger_out serial: a code written to the trigger box after the swap it follows."},
    {"trigger_failed", "text, failed",
     "eeg.trigger_out: writes to the trigger box failed (the recording keeps every onset)."},
};

}  // namespace

std::span<const LogEvent> logEvents() {
  return kEvents;
}

const LogEvent* findLogEvent(std::string_view name) {
  for (const LogEvent& e : logEvents())
    if (e.name == name) return &e;
  return nullptr;
}

std::string logEventsMarkdown() {
  std::ostringstream out;
  out << "| event | fields | what it says |\n| --- | --- | --- |\n";
  for (const LogEvent& e : logEvents()) {
    out << "| `" << e.name << "` | ";
    std::string fields(e.fields);
    for (size_t at = 0; !fields.empty();) {
      const size_t comma = fields.find(", ", at);
      out << "`" << fields.substr(at, comma - at) << "`";
      if (comma == std::string::npos) break;
      out << ", ";
      at = comma + 2;
    }
    out << " | " << e.meaning << " |\n";
  }
  return out.str();
}

}  // namespace arbci::session
