// Requests travel as records on the cycle, the way BCI2000's States carry what one module asks of
// another: a stage (or the experimenter, between frames) posts one; the stage that owns it acts on
// it in the next cycle, in the order posted. No stage calls another.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <opencv2/core/matx.hpp>

#include "arbci/bci/p300_model.h"
#include "arbci/core/run_labels.h"
#include "arbci/vision/threshold.h"

namespace arbci::session {

// The experimenter's Start, to the pre-flight check; the check passed, to the paradigm.
// `despite_quality`: the experimenter starts although the pre-flight questioned the EEG's quality.
struct StartRequest {
  bool despite_quality = false;
  // `despite_display`: the experimenter runs on a display the pre-flight found too slow, with the
  // flashes off limits annotated (no timing pauses this run).
  bool despite_display = false;
};
// To the timing gate: the policy (gates.timing) for the rest of this run, and why.
struct TimingPolicyRequest {
  std::string policy;
  std::string why;
};
struct BeginRequest {};
// The experimenter, to the paradigm.
// `reason`: why, when not the experimenter's own (a stage that pauses the run says why).
struct PauseRequest {
  std::string reason;
};
struct ResumeRequest {};
struct AbortRequest {};
struct EmergencyStopRequest {};  // the arm was already told to stop by the session
struct RetryStepRequest {};
struct SkipTrialRequest {};
struct EndSessionRequest {};
// The experimenter's answer to the calibration review (to the paradigm, and to the P300 and ErrP
// stages, which start their calibration data over on Recalibrate).
struct GoOnlineRequest {};
struct RecalibrateRequest {};

// To the robot stage. `time_s`: when it was asked for (a stepped arm starts it then).
// A grasp of `object` (marker id) where the cameras last saw it: `at` (robot frame; none: never
// seen, or not since the robot moved it), its pose then `pose_age_s` old. The robot stage never
// grasps at an unknown pose or one older than `max_pose_age_s` (it says why on the record, as any
// answer of the robot); `retry`: the experimenter's Retry step, done at once when the gripper
// already holds the object.
struct GraspRequest {
  int object = 0;
  std::optional<cv::Vec3d> at;
  double pose_age_s = 0.0;
  double max_pose_age_s = 0.0;  // the session's tracker.max_pose_age_s
  bool retry = false;
  double time_s = 0.0;
};
struct DropRequest {
  int trial = 0;
  std::pair<int, int> cell{0, 0};
  bool give_back = false;  // back where the object was grasped
  double time_s = 0.0;
};
struct RobotStopRequest {
  double time_s = 0.0;
};
struct RobotResetRequest {  // the experimenter's Reset
  double time_s = 0.0;
};
struct RobotResetIfLatchedRequest {  // before motions go on after a stop
  double time_s = 0.0;
};
struct RobotHomeRequest {
  double time_s = 0.0;
};
struct RobotReleaseRequest {  // the experimenter's Open gripper
  double time_s = 0.0;
};
// A put-down interrupted after the object was let go: the arm goes home and the put-down ends.
struct FinishPutDownRequest {
  double time_s = 0.0;
};
// The pre-flight check asks whether the backend answers STATUS.
struct RobotProbeRequest {
  double time_s = 0.0;
};

// To the P300 and ErrP stages.
struct TrainRequest {
  std::string method;
};
struct UseModelRequest {
  std::shared_ptr<const bci::P300Model> model;
};

// To the tracking and camera stages (the panels).
struct ThresholdRequest {
  vision::ThresholdSettings threshold;
};
struct ReferenceRequest {
  int id = 0;
  cv::Vec3d position;
};
struct HoldBoardRequest {
  bool show = false;
};

// The experimenter's note, typed in the window: into the recording (and the LSL Markers stream)
// as "Note: TEXT" at the moment it was made, and into the log (to the recording stage).
struct NoteRequest {
  std::string text;
};

// The start screen's subject, session, task and run: taken by the session at once (until Start),
// and on the record from the next cycle.
struct LabelsRequest {
  core::RunLabels labels;
};
// The settings edited on the start screen, for the run about to start (BCI2000's Set Config): to
// the window, which opens the session again with them (a running session keeps its own).
struct ApplySettingsRequest {
  std::string settings_json;  // the whole session document, as a session file holds it
};

using Request =
    std::variant<StartRequest, TimingPolicyRequest, BeginRequest, PauseRequest, ResumeRequest,
                 AbortRequest, EmergencyStopRequest, RetryStepRequest, SkipTrialRequest,
                 EndSessionRequest, GoOnlineRequest, RecalibrateRequest, GraspRequest, DropRequest,
                 RobotStopRequest, RobotResetRequest, RobotResetIfLatchedRequest, RobotHomeRequest,
                 RobotReleaseRequest, FinishPutDownRequest, RobotProbeRequest, TrainRequest,
                 UseModelRequest, ThresholdRequest, ReferenceRequest, HoldBoardRequest,
                 LabelsRequest, NoteRequest, ApplySettingsRequest>;

// The requests of one kind among `requests`, in order.
template <class T>
std::vector<const T*> requestsOf(const std::vector<Request>& requests) {
  std::vector<const T*> out;
  for (const Request& r : requests) {
    if (const T* found = std::get_if<T>(&r)) out.push_back(found);
  }
  return out;
}

}  // namespace arbci::session
