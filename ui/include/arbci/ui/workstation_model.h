// What the experimenter panels see of the running workstation and what they can change. The app
// implements it over its session; the panels read it every frame, so they show live data.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/bci/p300_model.h"
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
  virtual void useModel(const bci::P300Model& model) = 0;

  // Robot.
  virtual std::optional<robot::StatusPayload> robotStatus() = 0;
  virtual bool robotSilent() = 0;
  virtual std::vector<std::string> robotLog() = 0;
  virtual void emergencyStop() = 0;
  // After a latched stop (STOP or the watchdog): lift it, then send the arm home.
  virtual void robotReset() = 0;
  virtual void robotHome() = 0;

  // Session.
  virtual std::string phase() = 0;
  virtual int trial() = 0;
  virtual int trials() = 0;
  virtual int sequence() = 0;
  virtual bool started() = 0;
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
  virtual std::vector<StageTiming> timing() = 0;
  virtual std::vector<std::string> selections() = 0;  // one line per selection made
};

}  // namespace arbci::ui
