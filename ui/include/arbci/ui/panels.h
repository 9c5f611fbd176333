// The experimenter panels, each on the running workstation's live data.
#pragma once

#include <atomic>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/core/schema.h"
#include "arbci/ui/eeg_view.h"
#include "arbci/ui/image_view.h"
#include "arbci/ui/panel.h"
#include "arbci/ui/workstation_model.h"
#include "arbci/vision/calibration.h"

namespace arbci::ui {

// Threshold mode and value, the live binarised image beside the camera image, and the markers
// found with ID, confidence and pose.
class ThresholdPanel final : public Panel {
 public:
  explicit ThresholdPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Threshold"; }
  void draw() override;

 private:
  WorkstationModel& model_;
  ImageView camera_, binary_;
};

// Chessboard views with a live detection overlay, the coverage map, per-view and overall
// reprojection error, calibrate and save, an undistortion preview, and the reference marker.
class CalibrationPanel final : public Panel {
 public:
  explicit CalibrationPanel(WorkstationModel& model);
  const char* title() const override { return "Calibration"; }
  void draw() override;
  // What the buttons do, also for scripted use.
  void captureView();
  void calibrate();
  void holdBoard(bool show);

 private:
  WorkstationModel& model_;
  vision::IncrementalCalibrator calibrator_;
  std::optional<vision::CalibrationResult> result_;
  std::string last_view_, message_;
  std::vector<cv::Point2f> last_corners_;
  char save_path_[256] = "camera.yml";
  bool preview_undistorted_ = false, board_ = false;
  int reference_id_ = 0;
  float reference_position_[3] = {0.0f, 0.9f, 0.0f};
  ImageView view_, coverage_;
};

// Recordings, method and parameters; training with progress on a worker thread; the ERP averages
// and accuracy by sequences; saving the model and using it in the session.
class TrainingPanel final : public Panel {
 public:
  explicit TrainingPanel(WorkstationModel& model) : model_(model) {}
  ~TrainingPanel() override;
  const char* title() const override { return "Classifier training"; }
  void draw() override;
  void setRecordings(const std::string& files);
  // Trains as the button does; `wait` blocks until the result is in.
  void train(bool wait);

 private:
  struct Outcome {
    std::optional<bci::TrainingResult> result;
    std::optional<bci::P300Dataset> data;
    std::string error;
  };
  void startTraining();
  void initialise();
  void collect();
  void drawSessionErps();
  WorkstationModel& model_;
  char files_[1024] = "";
  char save_path_[256] = "model.json";
  int method_ = 0;  // in bci::classifiers()
  float window_end_ms_ = 0.0f, decimate_hz_ = 0.0f;
  bool initialised_ = false;  // from the session's settings, on first use
  std::atomic<double> progress_{0.0};
  std::mutex stage_mutex_;
  std::string stage_;
  std::future<Outcome> training_;
  std::optional<Outcome> outcome_;
  std::string message_;
};

// Connection, state, current command and progress, tool position, what the gripper holds,
// errors, and the emergency stop.
class RobotPanel final : public Panel {
 public:
  explicit RobotPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Robot"; }
  void draw() override;

 private:
  WorkstationModel& model_;
};

// The paradigm's state and phase, start/pause/resume/abort, the current sequence, the selections
// made, and the cycle's timing per stage with its overruns against the block budget.
class SessionPanel final : public Panel {
 public:
  explicit SessionPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Session"; }
  void draw() override;

 private:
  // "tracking lost" for the reference marker and each object seen too long ago.
  void trackingHealth();
  // Before Start: subject, session, task and run, and where the run will be written.
  void runLabels();
  void readLabels();   // the model's labels into the fields, once
  void checkLabels();  // what stops a start with them, and where the run goes
  bool labels_read_ = false;
  char subject_[64] = "", visit_[64] = "", task_[64] = "", run_[16] = "";
  std::string labels_refused_, labels_problem_, labels_target_;
  WorkstationModel& model_;
  std::vector<float> history_;
};

// The end-of-session summary: how it ended, accuracy, time per selection, bit rate, placements,
// late frames (the window opens it when the session ends).
class SummaryPanel final : public Panel {
 public:
  explicit SummaryPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Session summary"; }
  void draw() override;

 private:
  WorkstationModel& model_;
};

// Every EEG channel scrolling (scale, time base, the session's filter on or off), the stimulus
// onsets and the photodiode channel marked, each channel's quality graded with its finding.
class EegPanel final : public Panel {
 public:
  explicit EegPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "EEG"; }
  void draw() override;

 private:
  WorkstationModel& model_;
  EegView view_;
};

// The session's settings from the schema: each key with the widget of its type, its unit, range
// and documentation; every edit checked with the session file's messages; saved to a file.
class SettingsPanel final : public Panel {
 public:
  explicit SettingsPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Settings"; }
  void draw() override;

 private:
  void initialise();
  void check();
  bool editTable(const core::Table& table, nlohmann::json& object, const std::string& path);
  bool editKey(const core::Key& key, nlohmann::json& value, const std::string& path);
  WorkstationModel& model_;
  bool initialised_ = false;
  nlohmann::json document_;
  std::string error_, message_;
  char filter_[128] = "";
  char save_path_[512] = "session.json";
};

// Everything the experimenter was told (ends, faults, refusals, pauses, warnings), with its
// session time, filtered by severity and text.
class OperatorLogPanel final : public Panel {
 public:
  explicit OperatorLogPanel(WorkstationModel& model) : model_(model) {}
  const char* title() const override { return "Operator log"; }
  void draw() override;

 private:
  WorkstationModel& model_;
  std::vector<OperatorLine> lines_;
  bool show_[3] = {true, true, true};  // by OperatorLine::Severity
  char filter_[128] = "";
  bool scroll_to_end_ = false;
};

// The HMD view as the subject sees it (both eyes), mirrored for the experimenter.
class HmdPanel final : public Panel {
 public:
  HmdPanel(unsigned int texture, float aspect) : texture_(texture), aspect_(aspect) {}
  const char* title() const override { return "HMD view"; }
  void draw() override;

 private:
  unsigned int texture_;
  float aspect_;
};

// The emergency stop: a button that shows whatever panels are open (drawn by the shell).
void emergencyStopButton(WorkstationModel& model);

}  // namespace arbci::ui
