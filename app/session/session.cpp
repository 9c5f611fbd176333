#include "session/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <thread>

#include "session/hmd_composition.h"
#include "session/robot_connection.h"
#include "session/scene_source.h"
#include "session/session_summary.h"
#include "support/interrupt.h"
#include "support/status_line.h"

namespace arbci::app {
namespace {

PreflightSettings preflightSettingsOf(const SessionConfig& c, double eeg_rate_hz) {
  PreflightSettings p;
  p.eeg_rate_hz = eeg_rate_hz;
  if (c.cameras.source == "simulated") {
    p.camera_key = "cameras.source";
    p.camera_what = "the simulated cameras";
  } else if (!c.cameras.left.video.empty()) {
    p.camera_key = "cameras.left.video";
    p.camera_what = "the video " + c.cameras.left.video;
  } else {
    p.camera_key = "cameras.left.device";
    p.camera_what = "camera device " + std::to_string(c.cameras.left.device);
  }
  p.eeg_key = c.eeg.source == "file" ? "eeg.file" : "eeg.rate_hz";
  p.reference_id = c.world.reference_id;
  if (c.robot_backend == "simulated") {
    p.robot_key = "robot.backend";
    p.robot_what = "the simulated arm (arbci-robotd)";
  } else {
    p.robot_key = "robot.host, robot.port";
    p.robot_what = "the robot backend at " + c.robot_host + ":" + std::to_string(c.robot_port);
  }
  return p;
}

// How a run ended, for the summary: a run that ends in an emergency stop or a robot fault (the
// experimenter ends it, or a headless run stops waiting) is that; any other early end is aborted.
std::string endKindOf(const std::string& reason, bci::Phase phase) {
  if (reason == "finished" || reason == "timing check done") return "finished";
  if (phase == bci::Phase::EmergencyStop) return "estop";
  if (phase == bci::Phase::RobotFault) return "fault";
  return "aborted";
}

}  // namespace

namespace {

// A live amplifier (LSL, eegdev) runs on its own clock: a session on it cannot be stepped by a
// simulated clock, whoever asked for one (a headless run, a screenshot).
SessionOptions forSource(SessionOptions options, const SessionConfig& config) {
  if (config.eeg.live()) options.simulated_clock = false;
  return options;
}

}  // namespace

Session::Session(SessionConfig config, const SessionOptions& requested, render::GlContext& context)
    : config_(std::move(config)),
      options_(forSource(requested, config_)),
      context_(context),
      timing_(0.0),
      preflight_(PreflightSettings{}) {
  const SessionOptions& options = options_;
  if (options.seed) config_.eeg.seed = *options.seed;
  if (options.trials) config_.paradigm.trials = *options.trials;
  // The timing check: cued flashing until flashes_only_s, when the session ends.
  if (options.flashes_only_s > 0.0) config_.paradigm.flashes_only = true;
  // Every stage's settings, checked before anything starts.
  const SceneSettings scene_settings = SceneSettings::of(config_);
  const RobotSettings robot_settings = RobotSettings::of(config_);
  const EegStageSettings eeg_settings = EegStageSettings::of(config_);
  scene_settings.validate();
  robot_settings.validate();
  eeg_settings.validate();
  const ParadigmStageSettings paradigm_settings = ParadigmStageSettings::of(config_);

  timing_ = CycleTiming(1000.0 * config_.eeg.block_size / config_.eeg.rate_hz);
  folder_ = options.folder;
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (error)
    throw std::runtime_error(folder_.string() + ": cannot create the session folder (" +
                             error.message() + ")");
  log_ = std::make_unique<SessionLog>(folder_ / "log.jsonl");
  const int camera_every =
      std::max(1, static_cast<int>(std::lround(config_.display_hz / config_.cameras.rate_hz)));

  context.makeCurrent();
  std::unique_ptr<SceneSource> scene = openScene(scene_settings);

  // The robot: arbci-robotd on 127.0.0.1 with a fresh key, or a remote backend.
  RobotLink link =
      connectRobot(robot_settings, scene->simulatedRobot(), folder_, options.simulated_clock);
  robotd_ = std::move(link.backend);
  RobotChoreography::Hooks hooks;
  hooks.current_trial = [this]() -> TrialRecord& { return paradigm_->currentTrial(); };
  hooks.trial = [this](int trial) -> TrialRecord& { return paradigm_->trial(trial); };
  hooks.finished = [this](bool success, const std::string& why) {
    paradigm_->robotFinished(success, why);
  };
  hooks.object_moved = [this](int id) { vision_->objectMoved(id); };
  hooks.put_down_ended = [this] { paradigm_->putDownEnded(); };
  robot_ = std::make_unique<RobotChoreography>(std::move(link.client), link.stepped, *log_,
                                               config_.world, gridLayoutOf(config_.world.grid),
                                               camera_every, std::move(hooks));

  cameras_ = std::make_unique<CameraStage>(std::move(scene), *robot_);
  vision_ = std::make_unique<VisionStage>(TrackingSettings::of(config_), *cameras_);

  // EEG and the recording. Simulated clock: the EEG advances in lock-step with the frames;
  // otherwise the source runs on its own clock and a thread acquires it.
  const std::map<std::string, std::string> parameters = {
      {"Session", config_.source},
      {"Seed", std::to_string(config_.eeg.seed)},
      {"Paradigm", "single stimulus, " + std::to_string(config_.world.objects.size()) + " stimuli"},
      {"GridCodes",
       "100 + row (1-" + std::to_string(config_.world.grid.rows) + "), 100 + rows + column"},
      {"FlashMs", std::to_string(config_.paradigm.flash_ms)},
      {"IsiMs", std::to_string(config_.paradigm.isi_ms)},
      {"DisplayHz", std::to_string(config_.display_hz)},
      {"Classifier", config_.classifier_method},
      {"PhotodiodeChannel", config_.eeg.photodiode_channel},
      {"SoaMs", std::to_string(config_.paradigm.soaSeconds() * 1000.0)},
      {"StimulusCodeMap", stimulusCodeMap(config_.world, allSlots(config_.world))},
  };
  eeg_ = std::make_unique<EegStage>(eeg_settings, folder_ / "recording.bdf",
                                    options.simulated_clock, parameters, *log_, options.progress);
  stimulus_timing_ = std::make_unique<StimulusTiming>(config_.paradigm, eeg_->info().rate_hz);
  preflight_ = Preflight(preflightSettingsOf(config_, eeg_->info().rate_hz));

  paradigm_ = std::make_unique<ParadigmStage>(
      paradigm_settings, cycle_, options.simulated_clock, folder_ / "model.json",
      ParadigmStage::Services{*eeg_, *vision_, *robot_, *stimulus_timing_, *log_,
                              options.progress});
  hmd_ = std::make_unique<HmdStage>(
      HmdSettings::of(config_), folder_,
      HmdStage::Services{*vision_, *paradigm_, *robot_, *eeg_, *stimulus_timing_, timing_, *log_,
                         options.progress});
  stages_ = {eeg_.get(), cameras_.get(), vision_.get(), robot_.get(), paradigm_.get(), hmd_.get()};

  std::ofstream(folder_ / "session.json") << nlohmann::json{
      {"source", config_.source},
      {"seed", config_.eeg.seed},
      {"trials", config_.paradigm.trials}}.dump(2);
  log_->write(
      "session_started", 0.0,
      {{"folder", folder_.string()}, {"session", config_.source}, {"seed", config_.eeg.seed}});
  host_origin_ = options.simulated_clock ? 0.0 : bci::hostSeconds();
  cycle_.host_s = host_origin_;
  if (options.start_immediately) start();
}

Session::~Session() {
  try {
    if (!ended_) endRun("closed");
  } catch (const std::exception&) {
    // Nothing more can be saved from a destructor.
  }
}

void Session::start() {
  if (ended_ || paradigm().phase() != bci::Phase::Setup || preflightRunning()) return;
  log_->write("preflight_started", cycle_.time_s, {});
  preflight_.begin(observe());
}

PreflightObservation Session::observe() {
  PreflightObservation o;
  o.time_s = cycle_.time_s;
  o.wall_s = bci::hostSeconds();
  o.camera_frame = !cameras_->frames().left.empty();
  o.reference_age_s = vision_->world().referenceAge(cycle_.time_s);
  o.max_pose_age_s = config_.max_pose_age_s;
  o.eeg_samples = eeg_->samplesRecorded();
  o.robot_answered = robot_->answersStatus(cycle_.time_s);
  return o;
}

void Session::checkPreflight() {
  const Preflight::State state = preflight_.update(observe());
  if (state == Preflight::State::Passed) {
    log_->write("preflight", cycle_.time_s,
                {{"passed", true},
                 {"camera_frames", preflight_.cameraFrames()},
                 {"eeg_rate_hz", preflight_.eegRateHz()}});
    paradigm_->start();
  } else if (state == Preflight::State::Failed) {
    log_->write("preflight", cycle_.time_s,
                {{"passed", false}, {"failures", preflight_.failures()}});
    if (options_.progress) {
      *options_.progress << "\n";
      setStatusLineOpen(false);
      for (const std::string& f : preflight_.failures())
        *options_.progress << "pre-flight failed: " << f << "\n";
    }
    // Without an experimenter nothing can be fixed: the run ends before any flash.
    if (options_.start_immediately)
      endRun("pre-flight failed: " + preflight_.failures().front(), "aborted");
  }
}
void Session::pause() {
  if (refuse("pause", whyNotPause())) return;
  paradigm_->paradigm().pause();
}
void Session::resume() {
  if (refuse("resume", whyNotResume())) return;
  fault_since_ = -1.0;
  if (paradigm().interrupted()) robot_->resetIfLatched(cycle_.time_s);
  paradigm_->paradigm().resume();
}
void Session::abort() {
  paradigm_->paradigm().abort();
}
void Session::emergencyStop() {
  paradigm_->emergencyStop();
}
void Session::resetRobot() {
  robot_->reset(cycle_.time_s);
}
void Session::homeRobot() {
  if (refuse("home", whyNotHome())) return;
  robot_->home(cycle_.time_s);
}
void Session::releaseObject() {
  if (refuse("open the gripper", whyNotRelease())) return;
  robot_->release(cycle_.time_s);
}
void Session::retryStep() {
  if (refuse("retry the step", whyNotRetry())) return;
  fault_since_ = -1.0;
  log_->write("recovery", cycle_.time_s, {{"action", "retry step"}, {"trial", paradigm().trial()}});
  robot_->resetIfLatched(cycle_.time_s);
  paradigm_->retryStep();
}
void Session::skipTrial() {
  if (refuse("skip the trial", whyNotSkip())) return;
  fault_since_ = -1.0;
  log_->write("recovery", cycle_.time_s, {{"action", "skip trial"}, {"trial", paradigm().trial()}});
  robot_->resetIfLatched(cycle_.time_s);
  paradigm_->skipTrial();
}
void Session::endSession() {
  if (ended_) return;
  const bci::Phase phase = paradigm().phase();
  log_->write("recovery", cycle_.time_s, {{"action", "end session"}});
  const std::string kind = endKindOf("", phase);
  paradigm_->paradigm().abort();
  endRun(std::string("ended by the experimenter in: ") + bci::toString(phase), kind);
}

bool Session::refuse(const char* action, const std::string& why) {
  if (why.empty()) return false;
  log_->write("refused", cycle_.time_s, {{"action", action}, {"why", why}});
  return true;
}

std::string Session::whyArmNotClear() const {
  if (const auto held = robot_->holding())
    return "the arm holds object " + std::to_string(*held) + ": Open gripper or Retry step first";
  if (!robot_->atHome()) return "the arm is not home: Home first";
  return "";
}

std::string Session::whyNotResume() const {
  if (ended_) return "the session has ended";
  const bci::Phase phase = paradigm().phase();
  if (phase == bci::Phase::Paused) return "";
  const auto was = paradigm().interrupted();
  if (!was) return "nothing to resume: the session is not paused or stopped";
  if (*was != bci::Phase::Grasping && *was != bci::Phase::Dropping) return "";
  // Resume ends the interrupted trial and starts the next one: only with the arm clear.
  if (robot_->busy()) return "the arm is carrying out a command";
  return whyArmNotClear();
}

std::string Session::whyNotHome() const {
  if (ended_) return "the session has ended";
  // Outside a trial, or in a stop or fault: never in the middle of a trial's robot work.
  const bci::Phase phase = paradigm().phase();
  if (phase != bci::Phase::Setup && !paradigm().interrupted())
    return "only before the session starts or after an emergency stop or a robot fault";
  return robot_->whyNotMove();
}

std::string Session::whyNotPause() const {
  if (ended_) return "the session has ended";
  switch (paradigm().phase()) {
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

std::string Session::whyNotRelease() const {
  if (std::string why = whyNotHome(); !why.empty()) return why;
  return robot_->whyNotRelease();
}

std::string Session::whyNotRetry() const {
  if (ended_) return "the session has ended";
  const auto was = paradigm().interrupted();
  if (!was) return "nothing to retry: no emergency stop or robot fault";
  if (*was != bci::Phase::Grasping && *was != bci::Phase::Dropping) return "";
  if (std::string why = robot_->whyNotMove(); !why.empty()) return why;
  const auto held = robot_->holding();
  const std::optional<int> selected = paradigm_->selectedObjectId();
  if (*was == bci::Phase::Grasping && held && held != selected)
    return "the arm holds object " + std::to_string(*held) + ": Open gripper first";
  return "";
}

std::string Session::whyNotSkip() const {
  if (ended_) return "the session has ended";
  if (!paradigm().interrupted()) return "only after an emergency stop or a robot fault";
  if (robot_->busy()) return "the arm is carrying out a command";
  return whyArmNotClear();
}

void Session::beginCycle() {
  cycle_.frame = frame_;
  cycle_.time_s = options_.simulated_clock ? static_cast<double>(frame_) / config_.display_hz
                                           : bci::hostSeconds() - host_origin_;
  cycle_.host_s = host_origin_ + cycle_.time_s;
  // When this frame will be on screen: simulated, now; in a window, a period after the last one
  // (or now, when the cycle itself is late).
  cycle_.due_s = cycle_.time_s;
  if (!options_.simulated_clock && hmd_->lastPresented())
    cycle_.due_s = std::max(cycle_.time_s, *hmd_->lastPresented() + 1.0 / config_.display_hz);
}

bool Session::step() {
  if (ended_) return false;
  context_.makeCurrent();
  beginCycle();
  timing_.beginCycle();
  for (Stage* stage : stages_) {
    stage->step(cycle_);
    timing_.mark(stage->name());
  }
  if (preflightRunning()) checkPreflight();
  watchEegSource();
  if (options_.progress && !paradigm_->phaseChanges().empty()) showStatus();
  if (context_.isHeadless()) {
    context_.present();  // a window is presented by its owner, with the panels
    presented(options_.simulated_clock ? cycle_.time_s : bci::hostSeconds());
  }
  timing_.mark("present");
  recordCycleTime();
  endIfDone();
  if (options_.progress && frame_ % 600 == 0) showStatus();
  ++frame_;
  if (!options_.simulated_clock && context_.isHeadless()) {
    // --realtime without a display: pace the frames to the wall clock.
    const double wait = host_origin_ + frame_ / config_.display_hz - bci::hostSeconds();
    if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  }
  return !ended_;
}

void Session::watchEegSource() {
  using bci::Phase;
  const Phase phase = paradigm().phase();
  const std::string fault = eeg_->sourceFault();
  const double time = cycle_.time_s;
  if (!fault.empty()) {
    eeg_ok_since_ = -1.0;
    // Flashing (or cueing, or showing feedback) without EEG would decide on nothing: the
    // paradigm waits. The robot's own steps need no EEG and go on.
    const bool needs_eeg = phase == Phase::CalibrationCue || phase == Phase::CalibrationFlashing ||
                           phase == Phase::CalibrationFeedback || phase == Phase::ObjectFlashing ||
                           phase == Phase::CellFlashing || phase == Phase::ObjectSelected ||
                           phase == Phase::CellSelected;
    if (!paused_for_eeg_ && needs_eeg) {
      paradigm_->paradigm().pause();
      paused_for_eeg_ = true;
      log_->write("paused", time, {{"reason", "EEG source fault"}, {"fault", fault}});
      if (options_.progress)
        *options_.progress << "\npaused: " << fault << " (resumes 2 s after the EEG is back)\n";
    }
    return;
  }
  if (!paused_for_eeg_) return;
  if (phase != Phase::Paused) {
    paused_for_eeg_ = false;  // the experimenter resumed or ended it
    return;
  }
  if (eeg_ok_since_ < 0.0) eeg_ok_since_ = time;
  // Two seconds of signal again, then the sequence starts over (epochs touching the gap, and a
  // second before their window, are discarded).
  if (time - eeg_ok_since_ >= 2.0) {
    paradigm_->paradigm().resume();
    paused_for_eeg_ = false;
    log_->write("resumed", time, {{"reason", "EEG source delivering again"}});
    if (options_.progress) *options_.progress << "\nresumed: the EEG source delivers again\n";
  }
}

void Session::recordCycleTime() {
  const double total = timing_.endCycle();
  const nlohmann::json fields = {
      {"frame", cycle_.frame}, {"compute_ms", total}, {"stages", timing_.lastCycle()}};
  if (total > timing_.budgetMs()) log_->write("overrun", cycle_.time_s, fields);
  if (cycle_.frame % 6 == 0) log_->write("cycle", cycle_.time_s, fields);
}

void Session::endIfDone() {
  const double time = cycle_.time_s;
  // Without an experimenter, a fault or a stop ends the run after a while.
  const bci::Phase phase = paradigm().phase();
  if (phase == bci::Phase::RobotFault || phase == bci::Phase::EmergencyStop) {
    if (fault_since_ < 0.0) fault_since_ = time;
    if (options_.start_immediately && time - fault_since_ > options_.fault_wait_s)
      endRun(std::string("stopped waiting for the experimenter after: ") + bci::toString(phase));
  } else {
    fault_since_ = -1.0;
  }
  // The last placement is measured before the run ends (a status after the drop, or 3 s).
  if (phase == bci::Phase::Finished && !robot_->measuring(time)) endRun("finished");
  if (phase == bci::Phase::Aborted) endRun("aborted");
  if (options_.flashes_only_s > 0.0 && time >= options_.flashes_only_s) endRun("timing check done");
  if (options_.start_immediately && time > options_.max_session_s)
    endRun("the session ran past its time limit");
}

void Session::presented(double host_s) {
  hmd_->presented(host_s, host_origin_, cycle_.frame);
}

std::string Session::timingWarning() const {
  if (!stimulus_timing_->displayTooSlow()) return "";
  char text[160];
  std::snprintf(text, sizeof text, "display too slow: a frame every %.1f ms (configured %.1f ms)",
                *stimulus_timing_->medianFrameIntervalMs(), 1000.0 / config_.display_hz);
  return text;
}

std::string Session::eegClockLine() const {
  char text[160];
  std::snprintf(text, sizeof text, "EEG: lost samples %lld, clock drift %+.1f ppm, jitter %.2f ms",
                static_cast<long long>(eeg_->lostSamples()), eeg_->clockDriftPpm(),
                eeg_->clockJitterMs());
  const std::string source = eeg_->sourceLine();
  return source.empty() ? std::string(text) : std::string(text) + "\n" + source;
}

std::string Session::eegSourceFault() const {
  return eeg_->sourceFault();
}

std::int64_t Session::lateFrames() const {
  return stimulus_timing_->lateFrames();
}

void Session::setThreshold(const vision::ThresholdSettings& settings) {
  vision_->detector().setThreshold(settings);
}

void Session::setReference(int id, const cv::Vec3d& position) {
  vision_->setReference(id, config_.world.reference_size_m, position);
  log_->write("reference", cycle_.time_s,
              {{"id", id}, {"position", {position[0], position[1], position[2]}}});
}

bool Session::canHoldBoard() const {
  return cameras_->scene().canHoldBoard();
}

void Session::holdBoard(bool show) {
  cameras_->scene().holdBoard(show, cycle_.time_s);
}

void Session::useModel(const bci::P300Model& model) {
  eeg_->setModel(model);
  log_->write("model", cycle_.time_s, {{"method", model.method}, {"provenance", model.provenance}});
}

std::vector<std::string> Session::selectionLines() const {
  std::vector<std::string> lines;
  for (const TrialRecord& t : trials()) lines.push_back(selectionLine(t));
  return lines;
}

void Session::showStatus() const {
  if (!options_.progress) return;
  *options_.progress << "\r" << statusLine() << "      " << std::flush;
  setStatusLineOpen(true);
}

std::string Session::statusLine() const {
  char text[256];
  std::snprintf(text, sizeof text,
                "t=%.1f s  trial %d/%d  %s  cycle p50 %.1f ms  overruns %d  late frames %lld",
                cycle_.time_s, std::max(paradigm().trial(), 0), config_.paradigm.trials,
                bci::toString(paradigm().phase()), timing_.totalPercentiles().p50,
                timing_.overruns(), static_cast<long long>(lateFrames()));
  std::string line = text;
  for (const std::string& warning : {timingWarning(), trackingAlarm()}) {
    if (!warning.empty()) line.append("  [").append(warning).append("]");
  }
  return line;
}

std::string Session::trackingAlarm() const {
  std::vector<int> ids;
  for (const WorldObjectSettings& o : config_.world.objects) {
    if (robot_->holding() != o.id) ids.push_back(o.id);
  }
  return vision_->trackingAlarm(ids, cycle_.time_s);
}

void Session::endRun(const std::string& reason, const std::string& kind) {
  if (ended_) return;
  ended_ = true;
  end_reason_ = reason;
  end_kind_ = kind.empty() ? endKindOf(reason, paradigm().phase()) : kind;
  for (Stage* stage : stages_) stage->stop(cycle_, reason);
  log_->write("session_ended", cycle_.time_s, {{"reason", reason}});
  std::ofstream(folder_ / "summary.json") << summary().dump(2) << "\n";
  if (options_.progress) {
    *options_.progress << "\r" << statusLine() << "\nsession ended: " << reason << "\n";
    setStatusLineOpen(false);
  }
}

nlohmann::json Session::summary() const {
  const SessionFacts facts{config_.source,
                           config_.eeg.seed,
                           end_kind_,
                           end_reason_,
                           cycle_.time_s,
                           frame_,
                           static_cast<int>(config_.world.objects.size()),
                           config_.world.grid.rows * config_.world.grid.columns};
  nlohmann::json out =
      sessionSummary(facts, timing_, *stimulus_timing_, *eeg_, trials(), calibrationReport());
  if (config_.paradigm.errp)
    out["errp"] = errpSummary(paradigm_->errpCounts(), config_.errp.threshold, *eeg_);
  return out;
}

nlohmann::json Session::run() {
  while (step()) {
    if (interruptRequested()) abort();  // ends at the next frame, its summary saved
  }
  return summary();
}

}  // namespace arbci::app
