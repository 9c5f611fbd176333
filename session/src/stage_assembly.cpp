#include "stage_assembly.h"

#include <cmath>
#include <fstream>
#include <map>

#include "arbci/core/seeds.h"
#include "arbci/session/disk_estimate.h"
#include "arbci/session/scene_source.h"
#include "arbci/session/stages/camera_stage.h"
#include "arbci/session/stages/eeg_acquisition_stage.h"
#include "arbci/session/stages/errp_stage.h"
#include "arbci/session/stages/lsl_markers_stage.h"
#include "arbci/session/stages/p300_stage.h"
#include "arbci/session/stages/paradigm_stage.h"
#include "arbci/session/stages/preflight_stage.h"
#include "arbci/session/stages/presentation_stage.h"
#include "arbci/session/stages/recording_stage.h"
#include "arbci/session/stages/robot_stage.h"
#include "arbci/session/stages/signal_quality_stage.h"
#include "arbci/session/stages/timing_gate_stage.h"
#include "arbci/session/stages/tracking_stage.h"
#include "arbci/session/trial_intents.h"

namespace arbci::session {
namespace {

TrackingSettings trackingSettingsOf(const SessionConfig& c, SceneSource& scene) {
  TrackingSettings t{c.tracker.detector,
                     c.world.reference_id,
                     c.world.reference_size_m,
                     c.world.reference_position,
                     {},
                     c.tracker.max_pose_age_s,
                     scene.leftCamera(),
                     scene.rightCamera(),
                     scene.T_right_left(),
                     scene.warmUpFrames()};
  for (const WorldObjectSettings& o : c.world.objects) t.marker_size[o.id] = o.marker_m;
  return t;
}

PreflightSettings preflightSettingsOf(const SessionConfig& c, const SessionOptions& options,
                                      const bci::SignalInfo& eeg) {
  PreflightSettings p;
  p.eeg_rate_hz = eeg.rate_hz;
  const DiskEstimate disk = plannedRunBytes(c, eeg.channelCount(), eeg.rate_hz);
  p.disk_needed = disk.bytes;
  p.disk_what = disk.what;
  p.folder = options.folder.string();
  p.known_failures = options.display_failures;
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
  for (const WorldObjectSettings& o : c.world.objects) p.object_ids.push_back(o.id);
  // Nobody to ask: a question would only be a refusal that offers what cannot be done.
  p.quality_gate =
      c.gates.signal_quality == "ask" && !options.experimenter ? "refuse" : c.gates.signal_quality;
  p.bad_channels_allowed = c.gates.bad_channels_allowed;
  // A display that cannot hold its rate is asked about before Start where the timing gate would
  // pause the run for it (headless, the simulated display holds its rate by construction).
  if (options.experimenter && c.gates.timing == "pause") {
    p.display_hz = c.paradigm.display_hz;
    p.flash_ms = c.paradigm.flash_ms;
    p.soa_ms = c.paradigm.flash_ms + c.paradigm.isi_ms;
    p.display_question = true;
  }
  if (c.robot.backend == "simulated") {
    p.robot_key = "robot.backend";
    p.robot_what = "the simulated arm (arbci-robotd)";
  } else {
    p.robot_key = "robot.host, robot.port";
    p.robot_what = "the robot backend at " + c.robot.host + ":" + std::to_string(c.robot.port);
  }
  return p;
}

// What the recording says of the session at time 0 ("Param name=value").
std::map<std::string, std::string> recordingParameters(const SessionConfig& c) {
  return {
      {"Session", c.source},
      {"Seed", std::to_string(c.eeg.seed)},
      {"Paradigm", "single stimulus, " + std::to_string(c.world.objects.size()) + " stimuli"},
      {"GridCodes", "100 + row (1-" + std::to_string(c.world.grid.rows) + "), 100 + rows + column"},
      {"FlashMs", std::to_string(c.paradigm.flash_ms)},
      {"IsiMs", std::to_string(c.paradigm.isi_ms)},
      {"DisplayHz", std::to_string(c.paradigm.display_hz)},
      {"Classifier", c.classifier.training.method},
      {"PhotodiodeChannel", c.eeg.photodiode_channel},
      {"SoaMs", std::to_string(c.paradigm.soaSeconds() * 1000.0)},
      {"StimulusCodeMap", stimulusCodeMap(c.world, allSlots(c.world))},
      // For the recording's description (a BIDS export's _eeg.json): where the EEG came from
      // and the power line the online filter notched.
      {"EegSource", c.eeg.source},
      {"EegReference", c.eeg.reference},
      {"EegManufacturer", c.eeg.manufacturer},
      {"PowerLineHz", std::to_string(c.classifier.pipeline.filter.notch_hz)},
  };
}

ErrpStageSettings errpSettingsOf(const SessionConfig& c, const bci::SignalInfo& eeg_info) {
  ErrpStageSettings e;
  e.enabled = c.paradigm.errp;
  e.info = eeg_info;
  if (c.paradigm.errp) e.pipeline = c.errp.pipeline(c.classifier.pipeline, c.eeg.montage);
  e.training = c.errp.training();
  e.flash_s = c.paradigm.flashSeconds();
  e.model_file = c.classifier.model_file;
  e.threshold = c.errp.threshold;
  return e;
}

std::unique_ptr<LslMarkersStage> markersStageOf(const SessionConfig& c,
                                                const bci::lsl::LslConfig& lsl, double rate_hz,
                                                const StageServices& services) {
  if (!c.lsl.markers) return nullptr;
  // The stream's description says what the recording's parameters say (the layout).
  const std::map<std::string, std::string> parameters = recordingParameters(c);
  return std::make_unique<LslMarkersStage>(
      LslMarkersSettings{
          c.lsl.marker_stream, lsl, rate_hz, c.source, {parameters.begin(), parameters.end()}},
      services);
}

}  // namespace

SessionConfig configFor(SessionConfig config, const SessionOptions& options) {
  if (options.seed) config.eeg.seed = *options.seed;
  if (options.trials) config.paradigm.trials = *options.trials;
  if (options.flashes_only_s > 0.0) config.paradigm.flashes_only = true;
  return config;
}

SessionOptions optionsFor(SessionOptions options, const SessionConfig& config) {
  if (config.eeg.live()) options.clock = Clock::Mode::RealTime;
  return options;
}

// eeg.trigger_out "serial": the port, opened (nullptr for "none"). Throws SessionConfigError
// naming eeg.trigger.device and why it cannot be used.
static std::unique_ptr<TriggerOutput> openTriggerOutput(const SessionConfig& c) {
  if (c.eeg.trigger_out != "serial") return nullptr;
  TriggerSettings settings;
  triggerSchema().read(c.eeg.trigger, settings);
  try {
    return std::make_unique<TriggerOutput>(settings);
  } catch (const std::runtime_error& error) {
    throw SessionConfigError(c.source + ": eeg.trigger.device = \"" + settings.device +
                             "\": " + error.what());
  }
}

// The files the session file names; the devices are checked by opening them.
static void checkNamedFiles(const SessionConfig& c) {
  SceneSettings::of(c).validate();
  EegAcquisitionSettings{c.eeg, 0.0, c.source}.validate();
  if (!c.classifier.model_file.empty() && !std::filesystem::exists(c.classifier.model_file))
    throw SessionConfigError(c.source + ": classifier.model = \"" + c.classifier.model_file +
                             "\": no such file");
  checkRobotKey(c.robot, c.source);
}

void checkNamedResources(const SessionConfig& c) {
  checkNamedFiles(c);
  // Opened and closed again: before a run that is not made yet (the window's Apply).
  openTriggerOutput(c);
}

AssembledStages assembleStages(const SessionConfig& c, const SessionOptions& options, Clock& clock,
                               const std::filesystem::path& folder, const StageServices& services,
                               const DisplayFactory& display) {
  // Every stage's settings, checked before anything starts; the trigger port opened once, for
  // the run (opening a serial port can reset the box on it).
  checkNamedFiles(c);
  const SceneSettings scene_settings = SceneSettings::of(c);
  const EegAcquisitionSettings eeg_settings{c.eeg, c.paradigm.flashSeconds(), c.source,
                                            options.experimenter};
  bci::lsl::LslConfig lsl;
  if (c.eeg.live() || c.lsl.markers) lsl = c.lsl.config(c.source);
  const int camera_every =
      std::max(1, static_cast<int>(std::lround(c.paradigm.display_hz / c.cameras.rate_hz)));

  AssembledStages out;
  out.trigger = openTriggerOutput(c);
  std::unique_ptr<SceneSource> scene = sceneSources().at(c.cameras.source).make(scene_settings);
  // The robot: arbci-robotd on 127.0.0.1 with a fresh key, or a remote backend.
  RobotLink link = connectRobot(c.robot, scene->simulatedRobot(), folder, clock);
  auto robot = std::make_unique<RobotStage>(RobotStageSettings{c.world, camera_every},
                                            std::move(link), services);
  out.robot = robot.get();
  auto tracking = std::make_unique<TrackingStage>(trackingSettingsOf(c, *scene), services);
  auto cameras = std::make_unique<CameraStage>(std::move(scene));

  // EEG: acquired on its own clock (stepped: in lock-step with the frames), recorded, classified.
  auto eeg = std::make_unique<EegAcquisitionStage>(
      eeg_settings, openEegSource(c.eeg, lsl, clock, c.source), clock, services);
  auto recording = std::make_unique<RecordingStage>(
      RecordingSettings{folder / "recording.bdf", eeg->info(), recordingParameters(c)}, services);
  const bci::SignalInfo& eeg_info = eeg->eegInfo();
  auto quality = std::make_unique<SignalQualityStage>(
      SignalQualitySettings{eeg_info, c.gates.thresholds(c.classifier.pipeline.filter.notch_hz)});
  auto p300 = std::make_unique<P300Stage>(
      P300Settings{eeg_info,
                   c.classifier.pipeline,
                   c.classifier.training,
                   c.paradigm.flashSeconds(),
                   static_cast<int>(c.world.objects.size()),
                   c.classifier.model_file,
                   c.source,
                   c.learnsFromUse(),
                   c.paradigm.adapt && c.classifier.model_file.empty(),
                   {c.paradigm.learning_min_selections, c.paradigm.learning_min_consistency}},
      services);
  auto errp = std::make_unique<ErrpStage>(errpSettingsOf(c, eeg_info), services);
  std::unique_ptr<LslMarkersStage> markers = markersStageOf(c, lsl, eeg_info.rate_hz, services);
  auto presentation = std::make_unique<PresentationStage>(
      PresentationSettings{c.paradigm, eeg_info.rate_hz}, services);
  const GateSettings& g = c.gates;
  auto timing_gate = std::make_unique<TimingGateStage>(
      TimingGateSettings{g.timing,
                         timingLimitsOf(g.max_flash_ms, g.min_gap_ms, g.min_soa_ms, g.max_off_share,
                                        g.max_late_share, c.paradigm),
                         eeg_info.rate_hz, options.experimenter},
      services);
  auto preflight = std::make_unique<PreflightStage>(
      PreflightStageSettings{preflightSettingsOf(c, options, eeg_info), c.tracker.max_pose_age_s,
                             options.experimenter},
      services);
  auto paradigm = std::make_unique<ParadigmStage>(
      ParadigmStageSettings{c.paradigm, c.world, c.classifier.training.method, intendedTrials(c),
                            core::seedOf(c.eeg.seed, core::RandomStream::FlashOrder),
                            c.errp.threshold, folder / "model.json", options.experimenter,
                            c.tracker.max_pose_age_s, c.gates.review, c.gates.min_auc,
                            c.gates.max_retakes, c.learnsFromUse()},
      services);
  CycleRecord warm_up;
  tracking->publish(warm_up.tracking);
  warm_up.paradigm.slots = allSlots(c.world);
  std::unique_ptr<Stage> shown = display ? display(services, warm_up) : nullptr;

  // The order data flows: the last frame as shown; acquire; process; decide; render.
  out.stages.push_back(std::move(presentation));
  out.stages.push_back(std::move(eeg));
  out.stages.push_back(std::move(recording));
  out.stages.push_back(std::move(quality));
  out.stages.push_back(std::move(timing_gate));
  out.stages.push_back(std::move(p300));
  out.stages.push_back(std::move(errp));
  if (markers) out.stages.push_back(std::move(markers));
  out.stages.push_back(std::move(cameras));
  out.stages.push_back(std::move(robot));
  out.stages.push_back(std::move(tracking));
  out.stages.push_back(std::move(preflight));
  out.stages.push_back(std::move(paradigm));
  if (shown) out.stages.push_back(std::move(shown));
  return out;
}

}  // namespace arbci::session
