// The running session as the experimenter panels see it (ui::WorkstationModel over the session):
// what the last cycle's record holds, and the experimenter's actions as requests.
#pragma once

#include <filesystem>

#include "arbci/session/session.h"
#include "arbci/ui/workstation_model.h"

namespace arbci::app {

class SessionModel final : public ui::WorkstationModel {
 public:
  // `bids_root`: where the run is exported when it ends ("" for none).
  explicit SessionModel(session::Session& session, std::filesystem::path bids_root = {})
      : session_(session), bids_root_(std::move(bids_root)) {}

  cv::Mat cameraImage() override { return record().tracking.left_image; }
  cv::Mat binaryImage() override { return record().tracking.binary; }
  vision::DetectionResult detection() override { return record().tracking.detection; }
  vision::ThresholdSettings threshold() override { return threshold_; }
  void setThreshold(const vision::ThresholdSettings& settings) override;
  std::vector<ui::TrackedObject> trackedObjects() override;
  std::string worldStatus() override;

  vision::CameraModel camera() override { return record().tracking.left_camera; }
  bool canHoldBoard() override { return record().cameras.can_hold_board; }
  void holdBoard(bool show) override { session_.request(session::HoldBoardRequest{show}); }
  int referenceId() override;
  cv::Vec3d referencePosition() override;
  void setReference(int id, const cv::Vec3d& position) override {
    session_.request(session::ReferenceRequest{id, position});
  }

  std::optional<bci::P300Model> model() override;
  void useModel(const bci::P300Model& model) override;
  bci::TrainingSettings trainingSettings() override {
    return session_.config().classifier.training;
  }
  bci::PipelineSettings pipelineSettings() override {
    return session_.config().classifier.pipeline;
  }
  std::optional<bci::ErpCurves> sessionErp() override;
  std::optional<bci::ErpCurves> sessionErrpErp() override;
  std::optional<bci::EvaluationReport> sessionCalibration() override {
    return record().paradigm.calibration;
  }
  std::optional<double> errpThreshold() override {
    if (!session_.config().paradigm.errp) return std::nullopt;
    return session_.config().errp.threshold;
  }

  std::optional<robot::StatusPayload> robotStatus() override { return record().robot.status; }
  bool robotSilent() override { return record().robot.silent; }
  std::vector<std::string> robotLog() override;
  void emergencyStop() override { session_.request(session::EmergencyStopRequest{}); }
  std::string whyNot(Action action) override;
  void robotReset() override { session_.request(session::RobotResetRequest{session_.time()}); }
  void robotHome() override { session_.request(session::RobotHomeRequest{session_.time()}); }
  void openGripper() override { session_.request(session::RobotReleaseRequest{session_.time()}); }
  void retryStep() override { session_.request(session::RetryStepRequest{}); }
  void skipTrial() override { session_.request(session::SkipTrialRequest{}); }
  void endSession() override { session_.request(session::EndSessionRequest{}); }

  std::string phase() override;
  int trial() override { return record().paradigm.trial; }
  int trials() override { return session_.config().paradigm.trials; }
  int sequence() override { return record().paradigm.sequence; }
  bool started() override { return record().paradigm.phase != bci::Phase::Setup; }
  bool ended() override { return session_.ended(); }
  std::vector<std::string> preflight() override { return record().preflight.lines; }
  bool preflightRunning() override { return record().preflight.running; }
  std::vector<std::pair<std::string, std::string>> endSummary() override;
  std::string trackingAlarm() override;
  double maxPoseAgeS() override { return session_.config().tracker.max_pose_age_s; }
  std::optional<double> referenceAgeS() override;
  // With a subject and no run given (and no BIDS root): the next free run among the session
  // folders first (support/session_runs.h).
  void start() override;
  std::string eegImpedance() override { return record().eeg.impedance; }
  void pause() override { session_.request(session::PauseRequest{}); }
  void resume() override { session_.request(session::ResumeRequest{}); }
  void abort() override { session_.request(session::AbortRequest{}); }
  double sessionTime() override { return session_.time(); }
  double budgetMs() override { return session_.timing().budgetMs(); }
  int overruns() override { return session_.timing().overruns(); }
  long long lateFrames() override { return record().presentation.late_frames; }
  std::string timingWarning() override;
  std::string eegClockLine() override;
  std::string eegSourceFault() override { return record().eeg.fault; }
  std::vector<ui::StageTiming> timing() override;
  std::string reason() override;
  core::RunLabels labels() override { return session_.labels(); }
  std::string setLabels(const core::RunLabels& labels) override;
  std::string labelsProblem() override;
  std::string labelsTarget() override;
  const core::Table* settingsSchema() override;
  nlohmann::json settings() override { return session_.config().toJson(); }
  std::string checkSettings(const nlohmann::json& settings, const std::string& file) override;
  std::string saveSettings(const nlohmann::json& settings, const std::string& file) override;
  const bci::SignalScope* eegScope() override { return scope_ ? &*scope_ : nullptr; }
  std::string photodiodeChannel() override { return session_.config().eeg.photodiode_channel; }
  // After each session step: the cycle's EEG and flash onsets into the EEG view's scope.
  void ingest();
  std::vector<ui::OperatorLine> operatorLog() override;
  size_t operatorLogSize() override { return session_.operatorLog().messages().size(); }
  std::vector<std::string> selections() override;

 private:
  const session::CycleRecord& record() const { return session_.last(); }
  std::vector<std::pair<std::string, std::string>> summaryRows() const;
  session::Session& session_;
  std::filesystem::path bids_root_;
  std::vector<std::pair<std::string, std::string>> end_rows_;
  vision::ThresholdSettings threshold_;
  std::optional<bci::SignalScope> scope_;
};

// The session's status line for the terminal and the window's status bar: time, trial, phase,
// cycle time, overruns, late frames, and any warning.
std::string statusLine(const session::Session& session);
// "display too slow: ..." while the display cannot hold display_hz, else "".
std::string timingWarning(const session::Session& session);
// "" while the reference and every object not in the gripper are tracked within the allowed
// pose age; else "tracking lost: ...".
std::string trackingAlarm(const session::Session& session);

}  // namespace arbci::app
