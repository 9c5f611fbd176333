#include "arbci/session/experimenter.h"

namespace arbci::session {
namespace {

// The arm holds nothing and is home: a trial may start ("" when so, else what to do).
std::string whyArmNotClear(const RobotPart& robot) {
  if (const auto held = robot.holding())
    return "the arm holds object " + std::to_string(*held) + ": Open gripper or Retry step first";
  if (!robot.at_home) return "the arm is not home: Home first";
  return "";
}

std::string whyNotResume(const CycleRecord& last) {
  const ParadigmPart& p = last.paradigm;
  if (p.phase == bci::Phase::Paused && !p.waiting_for.empty())
    return "it resumes by itself once " + p.waiting_for + ", in the same selection";
  if (p.phase == bci::Phase::Paused) return "";
  if (!p.interrupted) return "nothing to resume: the session is not paused or stopped";
  if (*p.interrupted != bci::Phase::Grasping && *p.interrupted != bci::Phase::Dropping) return "";
  // Resume ends the interrupted trial and starts the next one: only with the arm clear.
  if (last.robot.busy) return "the arm is carrying out a command";
  return whyArmNotClear(last.robot);
}

std::string whyNotHome(const CycleRecord& last) {
  // Outside a trial, or in a stop or fault: never in the middle of a trial's robot work.
  if (last.paradigm.phase != bci::Phase::Setup && !last.paradigm.interrupted)
    return "only before the session starts or after an emergency stop or a robot fault";
  return last.robot.why_not_move;
}

std::string whyNotPause(const CycleRecord& last) {
  switch (last.paradigm.phase) {
    case bci::Phase::Setup:
      return "the session has not started";
    case bci::Phase::Paused:
      return "already paused";
    case bci::Phase::EmergencyStop:
    case bci::Phase::RobotFault:
      return "stopped: use the Robot panel's recovery";
    default:
      return "";
  }
}

std::string whyNotRetry(const CycleRecord& last) {
  const auto was = last.paradigm.interrupted;
  if (!was) return "nothing to retry: no emergency stop or robot fault";
  if (*was == bci::Phase::Setup)
    return "nothing to retry: the session had not started (Resume returns to set-up)";
  if (*was != bci::Phase::Grasping && *was != bci::Phase::Dropping) return "";
  if (!last.robot.why_not_move.empty()) return last.robot.why_not_move;
  const auto held = last.robot.holding();
  if (*was == bci::Phase::Grasping && held && held != last.paradigm.selected_object)
    return "the arm holds object " + std::to_string(*held) + ": Open gripper first";
  return "";
}

std::string whyNotSkip(const CycleRecord& last) {
  if (!last.paradigm.interrupted) return "only after an emergency stop or a robot fault";
  // The paradigm skips trials only (its calibration has none).
  if (last.paradigm.trial < 1)
    return "no trial to skip: the stop came before the first trial; Resume goes on";
  if (last.robot.busy) return "the arm is carrying out a command";
  return whyArmNotClear(last.robot);
}

}  // namespace

const char* toString(Action action) {
  switch (action) {
    case Action::Start:
      return "start";
    case Action::Pause:
      return "pause";
    case Action::Resume:
      return "resume";
    case Action::Abort:
      return "abort";
    case Action::EmergencyStop:
      return "emergency stop";
    case Action::ResetRobot:
      return "reset the robot";
    case Action::Home:
      return "home";
    case Action::OpenGripper:
      return "open the gripper";
    case Action::RetryStep:
      return "retry the step";
    case Action::SkipTrial:
      return "skip the trial";
    case Action::EndSession:
      return "end the session";
  }
  return "?";
}

std::string whyNot(Action action, const CycleRecord& last) {
  const bool ended = last.ended;
  // Once ended, the session no longer drives the arm (a simulated backend has stopped with it): a
  // STOP from here would be logged and reach nothing that listens.
  if (ended && (action == Action::EmergencyStop || action == Action::ResetRobot))
    return "the session has ended and no longer drives the arm; stop a real arm at its own "
           "emergency switch";
  if (action == Action::EmergencyStop || action == Action::ResetRobot) return "";
  if (ended) return "the session has ended";
  switch (action) {
    case Action::Start:
      if (last.paradigm.phase != bci::Phase::Setup) return "the session has started";
      if (last.preflight.running) return "the pre-flight check is running";
      return "";
    case Action::Pause:
      return whyNotPause(last);
    case Action::Resume:
      return whyNotResume(last);
    case Action::Home:
      return whyNotHome(last);
    case Action::OpenGripper:
      if (std::string why = whyNotHome(last); !why.empty()) return why;
      return last.robot.why_not_release;
    case Action::RetryStep:
      return whyNotRetry(last);
    case Action::SkipTrial:
      return whyNotSkip(last);
    default:
      return "";
  }
}

std::optional<Action> actionOf(const Request& request) {
  if (std::holds_alternative<StartRequest>(request)) return Action::Start;
  if (std::holds_alternative<PauseRequest>(request)) return Action::Pause;
  if (std::holds_alternative<ResumeRequest>(request)) return Action::Resume;
  if (std::holds_alternative<AbortRequest>(request)) return Action::Abort;
  if (std::holds_alternative<EmergencyStopRequest>(request)) return Action::EmergencyStop;
  if (std::holds_alternative<RobotResetRequest>(request)) return Action::ResetRobot;
  if (std::holds_alternative<RobotHomeRequest>(request)) return Action::Home;
  if (std::holds_alternative<RobotReleaseRequest>(request)) return Action::OpenGripper;
  if (std::holds_alternative<RetryStepRequest>(request)) return Action::RetryStep;
  if (std::holds_alternative<SkipTrialRequest>(request)) return Action::SkipTrial;
  if (std::holds_alternative<EndSessionRequest>(request)) return Action::EndSession;
  return std::nullopt;
}

std::string endKindOf(const std::string& reason, bci::Phase phase) {
  if (reason == "finished" || reason == "timing check done") return "finished";
  if (phase == bci::Phase::EmergencyStop) return "estop";
  if (phase == bci::Phase::RobotFault) return "fault";
  return "aborted";
}

}  // namespace arbci::session
