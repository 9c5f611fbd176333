// A session: the render-loop-synchronised cycle that ties every part together — a short loop
// over stages that are peers on one record per cycle (stage.h, cycle.h), in the order data flows:
// the last frame's presentation, the EEG (acquired, recorded, classified), the cameras, the
// robot, tracking, the pre-flight check, the paradigm, and the application's display. Each stage
// is timed; a cycle whose compute time exceeds the EEG block's is an overrun, counted and logged.
// The experimenter's actions are requests, refused with a reason when they cannot go, and acted
// on by their stage in the next cycle; an emergency stop reaches the arm at once.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/core/run_labels.h"
#include "arbci/session/clock.h"
#include "arbci/session/cycle.h"
#include "arbci/session/cycle_timing.h"
#include "arbci/session/experimenter.h"
#include "arbci/session/operator_log.h"
#include "arbci/session/session_config.h"
#include "arbci/session/session_log.h"
#include "arbci/session/stage.h"

namespace arbci::session {

class RobotStage;
class TriggerOutput;

struct SessionOptions {
  Clock::Mode clock = Clock::Mode::Stepped;  // a live amplifier always runs in real time
  std::filesystem::path folder;
  std::optional<int> trials;
  std::optional<std::uint64_t> seed;
  // Nobody at the window (headless): the run starts by itself, and ends on a failed pre-flight,
  // after `fault_wait_s` of a robot fault or emergency stop, or past `max_session_s`.
  bool experimenter = false;
  double fault_wait_s = 5.0;
  double max_session_s = 3600.0;
  // The display has no swap of its own to report (headless): the session stamps each frame
  // presented at the end of its cycle.
  bool presents_itself = true;
  // The timing check: flashes only (a calibration run that never ends) for this many seconds of
  // session time, then the session ends ("timing check done"); 0: a normal session.
  double flashes_only_s = 0.0;
  // What the display found wrong when its windows opened (a named HMD monitor that does not
  // exist), one line each naming its key: the pre-flight fails with these before any flash.
  std::vector<std::string> display_failures;
  std::ostream* progress = nullptr;
  // Who and which run (the start screen may change them until Start).
  core::RunLabels labels;
};

// The application's display stage (the HMD's renderer), made once the other stages exist;
// `warm_up` holds what tracking saw of the scene's warm-up frames, to draw once before the cycle
// is timed.
using DisplayFactory =
    std::function<std::unique_ptr<Stage>(const StageServices&, const CycleRecord& warm_up)>;

// Before a run: the files and devices the session file names can be used (a camera's video and
// calibration, the EEG file, the model, the robot's key). Throws SessionConfigError naming the
// key and the value.
void checkNamedResources(const SessionConfig& config);

// What an HMD runtime told of a frame it was given (hmd.output "openxr"): when it was handed
// over, the counterpart of a window's swap, and where the headset was when it was shown.
struct RuntimeFrame {
  double submitted_host_s = 0.0;
  // x, y, z (m) and the quaternion x, y, z, w, in the runtime's LOCAL space; none: not tracked.
  std::optional<std::array<double, 7>> head;
};

class Session {
 public:
  // Validates every stage's settings, creates the session folder, starts the robot backend
  // (simulated) and the recording. Throws std::runtime_error (or SessionConfigError naming the
  // key) with the reason.
  Session(SessionConfig config, const SessionOptions& options, const DisplayFactory& display);
  ~Session();

  // One displayed frame. Returns false once the session has ended.
  bool step();
  // The frame the last step() drew reached the screen at `host_s` (a window's owner calls it once
  // the buffer swap is done): its flashes are stamped with this instant's EEG sample. An HMD
  // runtime's predicted display time comes with the runtime's account of the frame, logged as
  // "hmd_frame" beside it.
  void presented(double host_s, const std::optional<RuntimeFrame>& runtime = std::nullopt);
  // Steps until the end (headless); `interrupted` (when given) aborts it. Returns the summary.
  nlohmann::json run(const std::function<bool()>& interrupted = {});
  // Ends the run now, between cycles, as a fault with `reason` (the window's display lost): the
  // stages stop and the summary is written, as at any end. Nothing once ended.
  void endNow(const std::string& reason) { endRun(reason, "fault"); }
  // Ends the run now as an Abort does, with `reason` (the window quit while the run went on).
  void abortNow(const std::string& reason) { endRun(reason, "aborted"); }

  // The experimenter: queued for the next cycle, or refused (and logged) with the reason
  // whyNot() gives. An emergency stop goes to the arm at once.
  bool request(Request request);
  std::string whyNot(Action action) const { return session::whyNot(action, last()); }
  // The run's labels: set until the session starts (then "" is returned), else why not.
  std::string setLabels(const core::RunLabels& labels);
  const core::RunLabels& labels() const { return options_.labels; }

  // What the last cycle produced (the panels read it).
  const CycleRecord& last() const { return records_[current_]; }
  const SessionConfig& config() const { return config_; }
  const CycleTiming& timing() const { return timing_; }
  const std::filesystem::path& folder() const { return folder_; }
  double time() const { return last().time_s; }
  std::int64_t frame() const { return frame_; }
  bool ended() const { return ended_; }
  const std::string& endReason() const { return end_reason_; }
  // How the run ended: "finished", "aborted", "estop" or "fault" (empty while it runs).
  const std::string& endKind() const { return end_kind_; }
  nlohmann::json summary() const;
  // Everything the experimenter has been told so far (ends, faults, refusals, warnings).
  const OperatorLog& operatorLog() const { return operator_log_; }

 private:
  void beginCycle();
  void recordCycleTime();
  // eeg.trigger_out: the bytes of the frame just presented, written and logged.
  void writeTriggers(const CycleRecord& record, double host_s);
  // What happened to the log's writing (failed, resumed), told the experimenter once.
  void tellLogNews(double time_s);
  void endIfDone();
  void endRun(const std::string& reason, const std::string& kind = "");

  SessionConfig config_;
  SessionOptions options_;
  Clock clock_;
  std::filesystem::path folder_;
  std::unique_ptr<SessionLog> log_;
  OperatorLog operator_log_;
  CycleTiming timing_;
  std::vector<std::unique_ptr<Stage>> stages_;  // in the order they run
  RobotStage* robot_ = nullptr;                 // for the emergency stop, which cannot wait
  // eeg.trigger_out: written at the swap itself, which no stage sees (they run before it).
  std::unique_ptr<TriggerOutput> trigger_;
  int trigger_failures_told_ = 0;
  std::int64_t trigger_writes_ = 0;
  double trigger_latency_max_ms_ = 0.0;
  CycleRecord records_[2];
  int current_ = 0;
  std::vector<Request> queued_;  // the experimenter's, since the last cycle
  std::int64_t frame_ = 0;       // the next frame
  double fault_since_ = -1.0;
  bool ended_ = false;
  std::string end_reason_, end_kind_;
};

}  // namespace arbci::session
