#include "arbci/session/stages/preflight_stage.h"

#include <filesystem>

namespace arbci::session {

PreflightStage::PreflightStage(const PreflightStageSettings& settings,
                               const StageServices& services)
    : settings_(settings), s_(services), preflight_(settings.check) {}

PreflightObservation PreflightStage::observe(const Cycle& cycle) const {
  PreflightObservation o;
  o.time_s = cycle.time_s;
  o.wall_s = bci::hostSeconds();
  o.camera_frame = !cycle.record.cameras.left.empty();
  if (const auto& world = cycle.record.tracking.world)
    o.reference_age_s = world->referenceAge(cycle.time_s);
  o.max_pose_age_s = settings_.max_pose_age_s;
  o.eeg_samples = cycle.record.recording.samples;
  o.robot_answered = cycle.record.robot.answered;
  o.robot_key_refused = cycle.record.robot.key_refused;
  o.disk_free = disk_free_;
  return o;
}

void PreflightStage::step(Cycle& cycle) {
  const bool begin = !requestsOf<StartRequest>(cycle.record.requests).empty() &&
                     cycle.previous.paradigm.phase == bci::Phase::Setup &&
                     preflight_.state() != Preflight::State::Running;
  if (begin) {
    s_.log.write("preflight_started", cycle.time_s, {});
    // Once a check: the disk does not fill in the seconds it lasts.
    disk_free_.reset();
    if (settings_.check.disk_needed > 0) {
      std::error_code error;
      const auto space = std::filesystem::space(settings_.check.folder, error);
      if (!error) disk_free_ = space.available;
    }
    preflight_.begin(observe(cycle));
  }
  if (preflight_.state() == Preflight::State::Running) {
    finish(cycle, preflight_.update(observe(cycle)));
    // The robot is asked again for the next observation.
    if (preflight_.state() == Preflight::State::Running)
      cycle.post(RobotProbeRequest{cycle.time_s});
  }
  cycle.record.preflight.running = preflight_.state() == Preflight::State::Running;
  cycle.record.preflight.lines = preflight_.lines();
}

void PreflightStage::finish(Cycle& cycle, Preflight::State state) {
  if (state == Preflight::State::Passed) {
    s_.log.write("preflight", cycle.time_s,
                 {{"passed", true},
                  {"camera_frames", preflight_.cameraFrames()},
                  {"eeg_rate_hz", preflight_.eegRateHz()}});
    s_.tell.say(cycle.time_s, Severity::Info, "pre-flight passed");
    cycle.post(BeginRequest{});
  } else if (state == Preflight::State::Failed) {
    s_.log.write("preflight", cycle.time_s,
                 {{"passed", false}, {"failures", preflight_.failures()}});
    for (const std::string& f : preflight_.failures())
      s_.tell.say(cycle.time_s, Severity::Error, "pre-flight failed: " + f);
    // Without an experimenter nothing can be fixed: the run ends before any flash.
    if (!settings_.experimenter)
      cycle.end("pre-flight failed: " + preflight_.failures().front(), "aborted");
  }
}

}  // namespace arbci::session
