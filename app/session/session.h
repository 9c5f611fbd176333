// A session: the render-loop-synchronised cycle that ties every part together, a short loop over
// its stages (session/stage.h), in the order data flows: the EEG (acquired, recorded, filtered,
// epoched, scored), the cameras, tracking, the robot, the paradigm (what the frame shows and what
// is decided), the HMD view. Every flash is stamped with the EEG sample index at its presentation.
// Each stage is timed; a cycle whose compute time exceeds the block budget is an overrun, counted
// and logged; a frame presented more than a period late is a late frame.
//
// Headless runs advance a simulated clock (display frames and EEG samples together) as fast as
// the machine allows, unless real time is asked for; windowed runs follow the wall clock.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "arbci/bci/paradigm.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/hmd_view.h"
#include "session/camera_stage.h"
#include "session/cycle_timing.h"
#include "session/eeg_stage.h"
#include "session/hmd_stage.h"
#include "session/paradigm_stage.h"
#include "session/preflight.h"
#include "session/robot_choreography.h"
#include "session/robot_process.h"
#include "session/session_config.h"
#include "session/session_log.h"
#include "session/stage.h"
#include "session/stimulus_timing.h"
#include "session/trial_record.h"
#include "session/vision_stage.h"

namespace arbci::app {

struct SessionOptions {
  bool simulated_clock = true;  // false: the wall clock (windowed, or --realtime)
  std::filesystem::path folder;
  std::optional<int> trials;
  std::optional<std::uint64_t> seed;
  // Without an experimenter (headless), how long a robot fault or an emergency stop waits before
  // the run ends (seconds of session time).
  double fault_wait_s = 5.0;
  double max_session_s = 3600.0;  // a safety bound on a headless run
  bool start_immediately = true;  // headless: no experimenter presses Start
  // The timing check: flashes only (a calibration run that never ends) for this many seconds of
  // session time, then the session ends ("timing check done"); 0: a normal session.
  double flashes_only_s = 0.0;
  bool close_window_when_ended = false;
  std::ostream* progress = nullptr;
};

class Session {
 public:
  // Validates every stage's settings, creates the session folder, starts the robot backend
  // (simulated) and the recording. Throws std::runtime_error (or SessionConfigError naming the
  // key) with the reason.
  Session(SessionConfig config, const SessionOptions& options, render::GlContext& context);
  ~Session();

  // One displayed frame. Returns false once the session has ended.
  bool step();
  // The frame the last step() drew reached the screen at `host_s` (bci::hostSeconds(); a window's
  // owner calls it once the buffer swap is done). Its flashes are stamped with this instant's EEG
  // sample; headless runs call it themselves.
  void presented(double host_s);
  std::int64_t lateFrames() const;
  // Non-empty while the display cannot hold display_hz.
  std::string timingWarning() const;
  // "EEG: lost samples N, clock drift X ppm, jitter Y ms".
  std::string eegClockLine() const;
  std::string eegSourceFault() const;
  // Steps until the end (headless); an interrupt (support/interrupt.h, when the caller watches
  // for one) aborts it. Returns the summary.
  nlohmann::json run();

  // Experimenter controls. Start runs the pre-flight check (session/preflight.h) and the
  // calibration run (or the trials) once it passes; a failed check is named in the log, on the
  // progress stream and in the panel, and ends a headless run before any flash.
  void start();
  std::vector<std::string> preflightLines() const { return preflight_.lines(); }
  bool preflightRunning() const { return preflight_.state() == Preflight::State::Running; }
  void pause();
  void resume();
  void abort();
  void emergencyStop();
  // The experimenter's recovery after an emergency stop or a robot fault (docs/session.md):
  // Reset lifts the robot's latched stop; Home parks the arm; Open gripper puts what it holds
  // back where it was taken from; Retry step asks again for the interrupted grasp or put-down (or
  // goes on with an interrupted selection); Skip trial ends the trial; End session ends the run,
  // which the summary records as "estop" or "fault". Each why-not says why the action cannot go
  // now ("" when it can): the panels show it, and the action refuses and logs it.
  void resetRobot();
  void homeRobot();
  void releaseObject();
  void retryStep();
  void skipTrial();
  void endSession();
  std::string whyNotPause() const;
  std::string whyNotResume() const;
  std::string whyNotHome() const;
  std::string whyNotRelease() const;
  std::string whyNotRetry() const;
  std::string whyNotSkip() const;
  // How the run ended: "finished", "aborted", "estop" or "fault" (empty while it runs).
  const std::string& endKind() const { return end_kind_; }

  // For the panels and the windowed app.
  const SessionConfig& config() const { return config_; }
  const bci::Paradigm& paradigm() const { return paradigm_->paradigm(); }
  VisionStage& vision() { return *vision_; }
  EegStage& eeg() { return *eeg_; }
  const CycleTiming& timing() const { return timing_; }
  const std::optional<robot::StatusPayload>& robotStatus() const { return robot_->status(); }
  bool robotSilent() const { return robot_->silent(); }
  const std::vector<std::string>& robotLog() const { return robot_->messages(); }
  const std::vector<TrialRecord>& trials() const { return paradigm_->trials(); }
  std::optional<bci::EvaluationReport> calibrationReport() const {
    return paradigm_->calibrationReport();
  }
  unsigned int hmdTexture() const { return hmd_->texture(); }  // the last HMD frame, for the UI
  render::Size hmdSize() const { return hmd_->size(); }
  const std::filesystem::path& folder() const { return folder_; }
  double time() const { return cycle_.time_s; }
  std::int64_t frame() const { return frame_; }
  std::string statusLine() const;
  // "" while the reference and every object not in the gripper are tracked within the allowed
  // pose age; else "tracking lost: ...".
  std::string trackingAlarm() const;
  bool ended() const { return ended_; }
  std::string endReason() const { return end_reason_; }
  // Experimenter settings from the panels.
  void setThreshold(const vision::ThresholdSettings& settings);
  void setReference(int id, const cv::Vec3d& position);
  bool canHoldBoard() const;
  void holdBoard(bool show);
  void useModel(const bci::P300Model& model);
  std::vector<std::string> selectionLines() const;
  // Writes the HMD view as it is now.
  void screenshot(const std::filesystem::path& path) { hmd_->screenshot(path); }
  nlohmann::json summary() const;

 private:
  // This cycle's frame number, time and due time.
  void beginCycle();
  void recordCycleTime();
  // A run without an experimenter ends on a fault after a while; every run at its end.
  void endIfDone();
  void endRun(const std::string& reason, const std::string& kind = "");
  // The arm holds nothing and is home: a trial may start ("" when so, else what to do).
  std::string whyArmNotClear() const;
  // Logs an experimenter's action the session refused, and why.
  bool refuse(const char* action, const std::string& why);
  PreflightObservation observe();
  void checkPreflight();
  // The status line on the progress stream, rewritten in place.
  void showStatus() const;

  SessionConfig config_;
  SessionOptions options_;
  render::GlContext& context_;
  std::filesystem::path folder_;
  std::unique_ptr<SessionLog> log_;
  std::unique_ptr<RobotProcess> robotd_;  // arbci-robotd, for a simulated robot
  CycleTiming timing_;
  std::unique_ptr<StimulusTiming> stimulus_timing_;
  CycleContext cycle_;        // the cycle being made (the last one, between frames)
  double host_origin_ = 0.0;  // session second 0 on the host clock (0 for a simulated clock)
  std::int64_t frame_ = 0;    // the next frame
  double fault_since_ = -1.0;
  // An EEG source fault pauses the paradigm; it resumes once the source has delivered 2 s again.
  void watchEegSource();
  bool paused_for_eeg_ = false;
  double eeg_ok_since_ = -1.0;
  bool ended_ = false;
  std::string end_reason_;
  std::string end_kind_;
  // The stages, constructed in this order (each may use those before it).
  std::unique_ptr<RobotChoreography> robot_;
  std::unique_ptr<CameraStage> cameras_;
  std::unique_ptr<VisionStage> vision_;
  std::unique_ptr<EegStage> eeg_;
  std::unique_ptr<ParadigmStage> paradigm_;
  std::unique_ptr<HmdStage> hmd_;
  std::vector<Stage*> stages_;  // in the order they run
  Preflight preflight_;
};

}  // namespace arbci::app
