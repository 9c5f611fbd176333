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
  for (int id : settings_.check.object_ids) {
    const auto& world = cycle.record.tracking.world;
    const auto state = world ? world->object(id) : std::nullopt;
    if (state && state->age(cycle.time_s) <= settings_.max_pose_age_s) o.objects_seen.push_back(id);
  }
  o.eeg_samples = cycle.record.recording.samples;
  o.robot_answered = cycle.record.robot.answered;
  o.robot_key_refused = cycle.record.robot.key_refused;
  o.disk_free = disk_free_;
  const QualityPart& quality = cycle.record.quality;
  o.channels = static_cast<int>(quality.channels.size());
  if (!quality.quality.empty()) o.bad_channels = quality.bad();
  if (cycle.record.presentation.shown) o.frame_host_s = cycle.record.presentation.host_s;
  return o;
}

void PreflightStage::step(Cycle& cycle) {
  const auto starts = requestsOf<StartRequest>(cycle.record.requests);
  const bool begin = !starts.empty() && cycle.previous.paradigm.phase == bci::Phase::Setup &&
                     preflight_.state() != Preflight::State::Running;
  if (begin) {
    // Accepting is the experimenter's answer to the question just asked, no other.
    Preflight::Accepted accepted;
    accepted.quality = starts.back()->despite_quality && preflight_.qualityQuestioned();
    accepted.display = starts.back()->despite_display && !preflight_.displayQuestion().empty() &&
                       preflight_.questioned();
    s_.log.write("preflight_started", cycle.time_s, {});
    // Once a check: the disk does not fill in the seconds it lasts.
    disk_free_.reset();
    if (settings_.check.disk_needed > 0) {
      std::error_code error;
      const auto space = std::filesystem::space(settings_.check.folder, error);
      if (!error) disk_free_ = space.available;
    }
    preflight_.begin(observe(cycle), accepted);
  }
  if (preflight_.state() == Preflight::State::Running) {
    finish(cycle, preflight_.update(observe(cycle)));
    // The robot is asked again for the next observation.
    if (preflight_.state() == Preflight::State::Running)
      cycle.post(RobotProbeRequest{cycle.time_s});
  }
  cycle.record.preflight.running = preflight_.state() == Preflight::State::Running;
  cycle.record.preflight.lines = preflight_.lines();
  if (preflight_.qualityQuestioned())
    cycle.record.preflight.questioned = cycle.record.quality.bad();
  if (preflight_.questioned())
    cycle.record.preflight.display_question = preflight_.displayQuestion();
}

void PreflightStage::logQuality(Cycle& cycle) {
  const QualityPart& quality = cycle.record.quality;
  const std::string verdict = preflight_.qualityVerdict();
  const std::vector<std::string> bad = quality.bad();
  quality_ = {{"verdict", verdict},
              {"gate", settings_.check.quality_gate},
              {"bad_channels", bad.size()},
              {"channels", quality.toJson()}};
  s_.log.write("signal_quality", cycle.time_s, quality_);
  // The recording (and a BIDS export's events) says what the channels were like at Start.
  std::string note = "Signal quality at Start: " + verdict + ", " + std::to_string(bad.size()) +
                     " of " + std::to_string(quality.channels.size()) + " channels bad";
  for (size_t i = 0; i < bad.size(); ++i) note += (i ? "; " : " (") + bad[i];
  if (!bad.empty()) note += ")";
  cycle.annotate(cycle.eeg_sample, note);
}

void PreflightStage::report(nlohmann::json& summary) const {
  summary["signal_quality"] = quality_.empty() ? nlohmann::json{{"verdict", "no Start"}} : quality_;
}

void PreflightStage::finish(Cycle& cycle, Preflight::State state) {
  if (state != Preflight::State::Running) logQuality(cycle);
  if (state == Preflight::State::Passed) {
    s_.log.write("preflight", cycle.time_s,
                 {{"passed", true},
                  {"camera_frames", preflight_.cameraFrames()},
                  {"eeg_rate_hz", preflight_.eegRateHz()}});
    s_.tell.say(cycle.time_s, Severity::Info, "pre-flight passed");
    if (preflight_.displayAccepted()) {
      // The experimenter's answer lasts for the run: the flashes off limits are annotated and
      // the timing gate does not pause for them.
      const std::string why =
          "the experimenter runs annotated on a display that cannot hold "
          "display_hz (" +
          preflight_.displayQuestion() + ")";
      s_.log.write("timing_policy", cycle.time_s, {{"policy", "annotate"}, {"why", why}});
      cycle.post(TimingPolicyRequest{"annotate", why});
    }
    cycle.post(BeginRequest{});
  } else if (state == Preflight::State::Failed) {
    s_.log.write("preflight", cycle.time_s,
                 {{"passed", false},
                  {"failures", preflight_.failures()},
                  {"questioned", preflight_.questioned()}});
    if (preflight_.questioned() && settings_.experimenter) {
      for (const std::string& f : preflight_.failures())
        s_.tell.say(cycle.time_s, Severity::Warning,
                    "pre-flight asks: " + f + " (answer with the button, or fix it and Start)");
      return;
    }
    for (const std::string& f : preflight_.failures())
      s_.tell.say(cycle.time_s, Severity::Error, "pre-flight failed: " + f);
    // Without an experimenter nothing can be fixed: the run ends before any flash.
    if (!settings_.experimenter)
      cycle.end("pre-flight failed: " + preflight_.failures().front(), "aborted");
  }
}

}  // namespace arbci::session
