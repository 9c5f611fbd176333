// The running session as the experimenter panels see it (ui::WorkstationModel over Session).
#pragma once

#include "arbci/ui/workstation_model.h"
#include "session/session.h"

namespace arbci::app {

class SessionModel final : public ui::WorkstationModel {
 public:
  explicit SessionModel(Session& session) : session_(session) {}

  cv::Mat cameraImage() override { return session_.vision().leftImage(); }
  cv::Mat binaryImage() override { return session_.vision().detector().lastBinaryImage(); }
  vision::DetectionResult detection() override { return session_.vision().lastDetection(); }
  vision::ThresholdSettings threshold() override { return threshold_; }
  void setThreshold(const vision::ThresholdSettings& settings) override;
  std::vector<ui::TrackedObject> trackedObjects() override;
  std::string worldStatus() override { return session_.vision().world().status(session_.time()); }

  vision::CameraModel camera() override { return session_.vision().leftCamera(); }
  bool canHoldBoard() override { return session_.canHoldBoard(); }
  void holdBoard(bool show) override { session_.holdBoard(show); }
  int referenceId() override { return session_.vision().world().reference().id; }
  cv::Vec3d referencePosition() override {
    return session_.vision().world().reference().T_robot_ref.translation;
  }
  void setReference(int id, const cv::Vec3d& position) override {
    session_.setReference(id, position);
  }

  std::optional<bci::P300Model> model() override { return session_.eeg().model(); }
  void useModel(const bci::P300Model& model) override { session_.useModel(model); }
  std::optional<bci::ErpCurves> sessionErp() override { return session_.eeg().trainedErp(); }
  std::optional<bci::ErpCurves> sessionErrpErp() override {
    return session_.eeg().trainedErrpErp();
  }
  std::optional<double> errpThreshold() override {
    if (!session_.config().paradigm.errp) return std::nullopt;
    return session_.config().errp.threshold;
  }

  std::optional<robot::StatusPayload> robotStatus() override { return session_.robotStatus(); }
  bool robotSilent() override { return session_.robotSilent(); }
  std::vector<std::string> robotLog() override { return session_.robotLog(); }
  void emergencyStop() override { session_.emergencyStop(); }
  std::string whyNot(Action action) override;
  void robotReset() override { session_.resetRobot(); }
  void robotHome() override { session_.homeRobot(); }
  void openGripper() override { session_.releaseObject(); }
  void retryStep() override { session_.retryStep(); }
  void skipTrial() override { session_.skipTrial(); }
  void endSession() override { session_.endSession(); }

  std::string phase() override;
  int trial() override { return session_.paradigm().trial(); }
  int trials() override { return session_.config().paradigm.trials; }
  int sequence() override { return session_.paradigm().sequence(); }
  bool started() override { return session_.paradigm().phase() != bci::Phase::Setup; }
  bool ended() override { return session_.ended(); }
  std::vector<std::string> preflight() override { return session_.preflightLines(); }
  bool preflightRunning() override { return session_.preflightRunning(); }
  std::vector<std::pair<std::string, std::string>> endSummary() override;
  std::string trackingAlarm() override { return session_.trackingAlarm(); }
  double maxPoseAgeS() override { return session_.config().max_pose_age_s; }
  std::optional<double> referenceAgeS() override {
    return session_.vision().world().referenceAge(session_.time());
  }
  void start() override { session_.start(); }
  void pause() override { session_.pause(); }
  void resume() override { session_.resume(); }
  void abort() override { session_.abort(); }
  double sessionTime() override { return session_.time(); }
  double budgetMs() override { return session_.timing().budgetMs(); }
  int overruns() override { return session_.timing().overruns(); }
  long long lateFrames() override { return session_.lateFrames(); }
  std::string timingWarning() override { return session_.timingWarning(); }
  std::string eegClockLine() override { return session_.eegClockLine(); }
  std::string eegSourceFault() override { return session_.eegSourceFault(); }
  std::vector<ui::StageTiming> timing() override;
  std::vector<std::string> selections() override { return session_.selectionLines(); }

 private:
  std::vector<std::pair<std::string, std::string>> summaryRows() const;
  Session& session_;
  std::vector<std::pair<std::string, std::string>> end_rows_;
  vision::ThresholdSettings threshold_;
};

}  // namespace arbci::app
