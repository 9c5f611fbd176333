// What the experimenter panels see of the running workstation and what they can change. The app
// implements it over its session; the panels read it every frame, so they show live data.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

#include <nlohmann/json.hpp>

#include "arbci/bci/erp.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/signal_scope.h"
#include "arbci/core/run_labels.h"
#include "arbci/core/schema.h"
#include "arbci/robot/protocol.h"
#include "arbci/vision/camera_model.h"
#include "arbci/vision/marker.h"
#include "arbci/vision/threshold.h"

namespace arbci::ui {

struct TrackedObject {
  int id = 0;
  cv::Vec3d position;  // robot frame, metres
  double age_s = 0.0;
  double reprojection_px = 0.0;
};

// One thing the experimenter was told: an end, a fault, a refusal, a pause, a warning.
struct OperatorLine {
  enum class Severity { Info, Warning, Error } severity = Severity::Info;
  double t = 0.0;  // session time, seconds
  std::string text;
};

struct StageTiming {
  std::string stage;
  double p50_ms = 0, p90_ms = 0, p99_ms = 0, max_ms = 0, last_ms = 0;
};

class WorkstationModel {
 public:
  virtual ~WorkstationModel() = default;

  // Cameras and the tracker.
  virtual cv::Mat cameraImage() = 0;  // the left camera's latest frame (BGR)
  virtual cv::Mat binaryImage() = 0;  // the tracker's binary image of that frame
  virtual vision::DetectionResult detection() = 0;
  virtual vision::ThresholdSettings threshold() = 0;
  virtual void setThreshold(const vision::ThresholdSettings& settings) = 0;
  virtual std::vector<TrackedObject> trackedObjects() = 0;
  virtual std::string worldStatus() = 0;  // e.g. whether the reference marker is in view

  // Calibration.
  virtual vision::CameraModel camera() = 0;
  // A simulated world can hold a chessboard up in front of the cameras (a new pose each call).
  virtual bool canHoldBoard() = 0;
  virtual void holdBoard(bool show) = 0;
  virtual int referenceId() = 0;
  virtual cv::Vec3d referencePosition() = 0;
  virtual void setReference(int id, const cv::Vec3d& position) = 0;

  // Classifier.
  virtual std::optional<bci::P300Model> model() = 0;
  // With ErrPs on: the posterior of an error above which a selection is rejected.
  virtual std::optional<double> errpThreshold() { return std::nullopt; }
  // The averages the session's own training used: flashes of the calibration run (target and
  // non-target), and the ErrP block's feedback (error and correct). None before it trains.
  virtual std::optional<bci::ErpCurves> sessionErp() { return std::nullopt; }
  virtual std::optional<bci::ErpCurves> sessionErrpErp() { return std::nullopt; }
  // The session's own model's cross-validation on its calibration run (none before it trains).
  virtual std::optional<bci::EvaluationReport> sessionCalibration() { return std::nullopt; }
  virtual void useModel(const bci::P300Model& model) = 0;
  // The session's classifier settings, where the Training panel starts (default: the schema's).
  virtual bci::TrainingSettings trainingSettings() { return {}; }
  virtual bci::PipelineSettings pipelineSettings() { return {}; }

  // Settings: the schema, this session's settings as a session file holds them, a check of an
  // edited copy ("" when valid, else the message a file with it would get, naming `file`), and
  // saving it ("saved FILE" or why not).
  virtual const core::Table* settingsSchema() { return nullptr; }
  virtual nlohmann::json settings() { return nlohmann::json::object(); }
  virtual std::string checkSettings(const nlohmann::json& /*settings*/,
                                    const std::string& /*file*/) {
    return "";
  }
  virtual std::string saveSettings(const nlohmann::json& /*settings*/, const std::string& file) {
    return "cannot save to " + file;
  }

  // Robot.
  virtual std::optional<robot::StatusPayload> robotStatus() = 0;
  virtual bool robotSilent() = 0;
  virtual std::vector<std::string> robotLog() = 0;
  virtual void emergencyStop() = 0;
  // Recovery after an emergency stop or a robot fault: Reset lifts the robot's latched stop;
  // Home parks the arm; Open gripper puts what it holds back where it was taken from; Retry step
  // asks again for the interrupted grasp or put-down; Skip trial ends the trial; End session
  // ends the run. whyNot() says why an action cannot go now ("" when it can).
  enum class Action {
    Start,
    Pause,
    Resume,
    Abort,
    EmergencyStop,
    ResetRobot,
    Home,
    OpenGripper,
    RetryStep,
    SkipTrial,
    EndSession
  };
  virtual std::string whyNot(Action action) = 0;
  virtual void robotReset() = 0;
  virtual void robotHome() = 0;
  virtual void openGripper() = 0;
  virtual void retryStep() = 0;
  virtual void skipTrial() = 0;
  virtual void endSession() = 0;

  // Who and which run: editable until Start. setLabels() takes them ("" when taken, else why
  // not); labelsProblem() says what stops a start with them ("" when none); labelsTarget() where
  // the run will be written ("BIDS: sub-07/eeg, ..., run 2 (the next free)", or the folder).
  virtual core::RunLabels labels() { return {}; }
  virtual std::string setLabels(const core::RunLabels& /*labels*/) { return "not here"; }
  virtual std::string labelsProblem() { return ""; }
  virtual std::string labelsTarget() { return ""; }

  // Session.
  virtual std::string phase() = 0;
  virtual int trial() = 0;
  virtual int trials() = 0;
  virtual int sequence() = 0;
  virtual bool started() = 0;
  // The pre-flight check that Start runs first (cameras, reference, EEG, robot): its lines, and
  // whether it is still checking.
  virtual std::vector<std::string> preflight() = 0;
  virtual bool preflightRunning() = 0;
  virtual bool ended() = 0;
  // Once ended: how (finished, aborted, estop, fault) and the summary's figures as label/value rows
  // (accuracy, time per selection, bit rate, placements, late frames).
  virtual std::vector<std::pair<std::string, std::string>> endSummary() = 0;
  // Tracking health: "" while the reference marker and every object were seen within the
  // allowed pose age, else e.g. "tracking lost: reference 0, object 40 (1.3 s)".
  virtual std::string trackingAlarm() = 0;
  virtual double maxPoseAgeS() = 0;
  virtual std::optional<double> referenceAgeS() = 0;  // since the reference marker was seen
  virtual void start() = 0;
  virtual void pause() = 0;
  virtual void resume() = 0;
  virtual void abort() = 0;
  virtual double sessionTime() = 0;
  virtual double budgetMs() = 0;
  virtual int overruns() = 0;
  // Frames presented more than a period late, and a warning while the display cannot hold its
  // rate (empty otherwise).
  virtual long long lateFrames() { return 0; }
  virtual std::string timingWarning() { return ""; }
  // The EEG time base: samples lost (gaps, overflows), the amplifier clock's drift and jitter.
  virtual std::string eegClockLine() { return ""; }
  // The last seconds of every channel with its quality (none before the first samples).
  virtual const bci::SignalScope* eegScope() { return nullptr; }
  virtual std::string photodiodeChannel() { return ""; }  // "" when none
  // Electrode impedances where the source reports them ("" when it does not).
  virtual std::string eegImpedance() { return ""; }
  // Why a live EEG source delivers nothing now (e.g. its LSL stream is gone); empty when well.
  virtual std::string eegSourceFault() { return ""; }
  virtual std::vector<StageTiming> timing() = 0;
  // Why the session is not going as planned now (a pause, a failed training, a grasp refused),
  // empty when it is; once ended, how and why, in the summary's words ("estop (ended by the
  // experimenter)").
  virtual std::string reason() { return ""; }
  // Everything the experimenter has been told, oldest first.
  virtual std::vector<OperatorLine> operatorLog() { return {}; }
  // How many lines operatorLog() holds (cheap: a panel asks every frame).
  virtual size_t operatorLogSize() { return 0; }
  virtual std::vector<std::string> selections() = 0;  // one line per selection made
};

}  // namespace arbci::ui
