#include "session/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "arbci/bci/evaluation.h"
#include "arbci/render/framebuffer.h"
#include "arbci/robot/key_file.h"
#include "session/hmd_composition.h"
#include "session/image_writer.h"
#include "session/robot_process.h"
#include "session/scene_source.h"
#include "session/session_log.h"
#include "session/stimulus_timing.h"
#include "session/trial_intents.h"
#include "support/interrupt.h"

namespace arbci::app {

struct Session::Impl {
  render::GlContext& context;
  std::unique_ptr<render::Framebuffer> hmd_fbo;
  std::unique_ptr<render::HmdView> hmd;
  std::unique_ptr<SceneSource> scene;  // what the cameras see: simulated or real
  std::unique_ptr<RobotProcess> robotd;
  // Session second 0 on the host clock (0 for a simulated clock, which is its own host clock).
  double host_origin = 0.0;
  // The frame being drawn: when it is due on screen, what it lights, which flashes it shows first.
  double due = 0.0;
  std::set<int> lit;
  std::vector<int> first_shown;
  bool frame_pending = false;
  std::optional<double> last_presented;
  bool patch_lit = false;  // as last told to the EEG source
  bool warned_slow_display = false;
  std::unique_ptr<StimulusTiming> stimulus_timing;
  double last_trial_end = 0.0;   // where the next trial's time starts (session seconds)
  std::int64_t lost_logged = 0;  // lost EEG samples already in the log
  double longest_frame_while_training = 0.0;  // seconds between presentations
  int frames_while_training = 0;
  double training_since = 0.0;  // session seconds
  std::unique_ptr<SessionLog> log;
  int camera_every = 2;  // display frames per camera frame
  std::vector<TrialIntent> intended;
  int selection_flashes = 0;
  bool selection_objects = true;
  std::optional<std::string> screenshot_name;
  ImageWriter images;
  // The last frame drawn: an identical frame is not drawn again (the framebuffer still holds it).
  std::string last_hmd_signature;
  bool hmd_redrawn = false;  // this frame drew the HMD view (else the framebuffer still holds it)
  bool screenshot_needs_flash = false;
  double fault_since = -1.0;
  bci::FrameStimulus last_stimulus;
  // The objects a trial's selection offers, as indices into the session's objects: stimulus code
  // k is slots[k - 1]. Those the cameras see; chosen before each trial.
  std::vector<size_t> slots;

  explicit Impl(render::GlContext& c) : context(c) {}
};

namespace {

std::string phaseSlug(bci::Phase phase) {
  switch (phase) {
    case bci::Phase::CalibrationFlashing:
      return "calibration";
    case bci::Phase::ObjectFlashing:
      return "1_objects_flashing";
    case bci::Phase::ObjectSelected:
      return "2_object_selected";
    case bci::Phase::Grasping:
      return "3_grasping";
    case bci::Phase::CellFlashing:
      return "4_grid_flashing";
    case bci::Phase::CellSelected:
      return "5_cell_selected";
    case bci::Phase::Dropping:
      return "6_putting_down";
    case bci::Phase::RobotFault:
      return "robot_fault";
    case bci::Phase::Finished:
      return "finished";
    default:
      return "";
  }
}

}  // namespace

Session::Session(SessionConfig config, const SessionOptions& options, render::GlContext& context)
    : impl_(std::make_unique<Impl>(context)),
      config_(std::move(config)),
      options_(options),
      timing_(0.0) {
  Impl& m = *impl_;
  if (options.seed) config_.eeg.seed = *options.seed;
  if (options.trials) config_.paradigm.trials = *options.trials;
  // The timing check: cued flashing until flashes_only_s, when the session ends.
  if (options.flashes_only_s > 0.0) config_.paradigm.flashes_only = true;
  config_.checkResources();
  timing_ = CycleTiming(1000.0 * config_.eeg.block_size / config_.eeg.rate_hz);
  folder_ = options.folder;
  std::error_code error;
  std::filesystem::create_directories(folder_, error);
  if (error)
    throw std::runtime_error(folder_.string() + ": cannot create the session folder (" +
                             error.message() + ")");
  m.log = std::make_unique<SessionLog>(folder_ / "log.jsonl");
  m.camera_every =
      std::max(1, static_cast<int>(std::lround(config_.display_hz / config_.cameras.rate_hz)));

  m.intended = intendedTrials(config_);

  // Cameras.
  context.makeCurrent();
  m.scene = openScene(config_);
  vision_ = std::make_unique<VisionStage>(TrackingSettings::of(config_), m.scene->leftCamera(),
                                          m.scene->rightCamera(), m.scene->T_right_left());

  // The robot: arbci-robotd on 127.0.0.1 with a fresh key, or a remote backend.
  robot::Key key;
  robot::Endpoint endpoint;
  if (config_.robot_backend == "simulated") {
    key = robot::generateKey();
    const auto key_file = folder_ / "robot.key";
    robot::saveKey(key_file, key);
    const robot::RobotConfig robot_config = m.scene->simulatedRobot();
    std::ofstream(folder_ / "robot.json") << robot_config.toJson();
    // A simulated clock steps the arm too (the robot follows the session, frame by frame).
    m.robotd = std::make_unique<RobotProcess>(robotdNextToMe(), key_file, folder_ / "robot.json",
                                              config_.robot_speed_factor, folder_,
                                              options.simulated_clock);
    std::ofstream(folder_ / "robotd.pid") << m.robotd->pid() << "\n";
    endpoint = robot::Endpoint::resolve("127.0.0.1", m.robotd->port());
  } else {
    key = robot::loadKey(config_.robot_key_file);
    endpoint = robot::Endpoint::resolve(config_.robot_host, config_.robot_port);
  }
  RobotChoreography::Hooks hooks;
  hooks.current_trial = [this]() -> TrialRecord& { return currentTrial(); };
  hooks.trial = [this](int trial) -> TrialRecord& {
    return trials_.at(static_cast<size_t>(trial - 1));
  };
  hooks.finished = [this](bool success, const std::string& why) {
    paradigm_->robotFinished(success, why);
  };
  hooks.object_moved = [this](int id) { vision_->objectMoved(id); };
  hooks.put_down_ended = [this] {
    chooseSelectableObjects();
    paradigm_->robotFinished(true, "");
  };
  const bool stepped = config_.robot_backend == "simulated" && options.simulated_clock;
  robot_ = std::make_unique<RobotChoreography>(std::make_unique<robot::RobotClient>(endpoint, key),
                                               stepped, *m.log, config_.world, gridLayout(),
                                               m.camera_every, std::move(hooks));

  // EEG and the recording.
  std::map<std::string, std::string> parameters = {
      {"Session", config_.source},
      {"Seed", std::to_string(config_.eeg.seed)},
      {"Paradigm", "single stimulus, " + std::to_string(config_.world.objects.size()) + " stimuli"},
      {"GridCodes",
       "100 + row (1-" + std::to_string(config_.world.grid.rows) + "), 100 + rows + column"},
      {"FlashMs", std::to_string(config_.paradigm.flash_ms)},
      {"IsiMs", std::to_string(config_.paradigm.isi_ms)},
      {"DisplayHz", std::to_string(config_.display_hz)},
      {"Classifier", config_.classifier_method},
  };
  parameters["PhotodiodeChannel"] = config_.eeg.photodiode_channel;
  parameters["SoaMs"] = std::to_string(config_.paradigm.soaSeconds() * 1000.0);
  // Simulated clock: the EEG advances in lock-step with the frames; otherwise the source runs on
  // its own clock and a thread acquires it.
  eeg_ = std::make_unique<EegStage>(EegStageSettings::of(config_), folder_ / "recording.bdf",
                                    options.simulated_clock, parameters);
  m.stimulus_timing = std::make_unique<StimulusTiming>(config_.paradigm, eeg_->info().rate_hz);
  if (!config_.model_file.empty()) eeg_->setModel(bci::P300Model::load(config_.model_file));

  paradigm_ = std::make_unique<bci::Paradigm>(
      config_.paradigm, static_cast<int>(config_.world.objects.size()), config_.world.grid.rows,
      config_.world.grid.columns, config_.eeg.seed + 11);
  for (size_t i = 0; i < config_.world.objects.size(); ++i) m.slots.push_back(i);
  m.hmd = std::make_unique<render::HmdView>();
  m.hmd->setUndistort(config_.undistort);
  m.hmd_fbo =
      std::make_unique<render::Framebuffer>(render::Size{config_.hmd_width, config_.hmd_height});
  std::ofstream(folder_ / "session.json") << nlohmann::json{
      {"source", config_.source},
      {"seed", config_.eeg.seed},
      {"trials", config_.paradigm.trials}}.dump(2);
  // Warm-up: Mesa compiles its shader variants and the tracker builds its tables on first use;
  // that happens here, before the cycle's time is measured.
  for (const auto& [left, right] : m.scene->warmUpFrames()) vision_->process(0.0, left, right);
  // Every kind of overlay once: highlights in each state, the grid with rows, columns and cells.
  bci::FrameStimulus all;
  all.grid_visible = true;
  all.phase = bci::Phase::CellFlashing;
  all.lit = {1, config_.world.grid.rows + 1};
  all.cued_object = 1;
  all.selected_object = 2;
  all.selected_cell = std::make_pair(1, 1);
  renderHmd(all);
  all.phase = bci::Phase::ObjectFlashing;
  renderHmd(all);
  renderHmd(bci::FrameStimulus{});
  m.log->write(
      "session_started", 0.0,
      {{"folder", folder_.string()}, {"session", config_.source}, {"seed", config_.eeg.seed}});
  m.host_origin = options.simulated_clock ? 0.0 : bci::hostSeconds();
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
  if (paradigm_->phase() != bci::Phase::Setup) return;
  chooseSelectableObjects();
  paradigm_->start(!eeg_->hasModel());
}
void Session::pause() {
  paradigm_->pause();
}
void Session::resume() {
  impl_->fault_since = -1.0;
  paradigm_->resume();
}
void Session::abort() {
  paradigm_->abort();
}
void Session::emergencyStop() {
  impl_->log->write("emergency_stop", time_, {{"by", "experimenter"}});
  paradigm_->emergencyStop();
  // The paradigm asks for the robot's STOP; it goes out now, not a frame later.
  handleParadigmEvents();
}

void Session::resetRobot() {
  robot_->reset(time_);
}

void Session::homeRobot() {
  robot_->home(time_);
}

TrialRecord& Session::currentTrial() {
  const int trial = std::max(1, paradigm_->trial());
  while (static_cast<int>(trials_.size()) < trial) {
    TrialRecord r;
    r.trial = static_cast<int>(trials_.size()) + 1;
    const TrialIntent& intent = impl_->intended[static_cast<size_t>(r.trial - 1)];
    r.intended_object = intent.object;
    r.intended_cell = {intent.row, intent.column};
    r.started_s = impl_->last_trial_end;
    trials_.push_back(r);
  }
  return trials_[static_cast<size_t>(trial - 1)];
}

bool Session::step() {
  if (ended_) return false;
  Impl& m = *impl_;
  m.context.makeCurrent();
  time_ = options_.simulated_clock ? static_cast<double>(frame_) / config_.display_hz
                                   : bci::hostSeconds() - m.host_origin;
  // When this frame will be on screen: simulated, now; in a window, a period after the last one
  // (or now, when the cycle itself is late).
  m.due = time_;
  if (!options_.simulated_clock && m.last_presented)
    m.due = std::max(time_, *m.last_presented + 1.0 / config_.display_hz);
  timing_.beginCycle();

  // EEG: everything that has arrived (simulated: generated up to now).
  if (options_.simulated_clock) eeg_->advanceTo(time_);
  eeg_->poll();
  if (eeg_->lostSamples() != m.lost_logged) {
    m.log->write("lost_samples", time_,
                 {{"total", eeg_->lostSamples()}, {"new", eeg_->lostSamples() - m.lost_logged}});
    if (options_.progress)
      *options_.progress << "\nwarning: " << eeg_->lostSamples() - m.lost_logged
                         << " EEG samples lost (see the recording's annotations)\n";
    m.lost_logged = eeg_->lostSamples();
  }
  timing_.mark("eeg");
  collectTraining();

  // Cameras and tracking.
  const SceneSource::Frames frames = m.scene->capture(frame_, time_, robot_->status());
  if (frames.any()) {
    timing_.mark("cameras");
    vision_->take(time_, frames);
    timing_.mark("tracking");
  }

  // Robot: up to this frame's time (a stepped arm too), its events, a placement to measure.
  robot_->step(frame_, time_);
  timing_.mark("robot");

  // Paradigm: this frame's stimuli, and what it asks for.
  const bci::FrameStimulus stimulus = paradigm_->frame(frame_, m.due);
  m.last_stimulus = stimulus;
  m.lit = stimulus.lit;
  m.first_shown.clear();
  m.frame_pending = true;
  handleParadigmEvents();
  decideIfReady();
  timing_.mark("paradigm");

  renderHmd(stimulus);
  timing_.mark("render");
  if (m.context.isHeadless()) {
    m.context.present();  // a window is presented by its owner, with the panels
    presented(options_.simulated_clock ? time_ : bci::hostSeconds());
  }
  timing_.mark("present");
  const double total = timing_.endCycle();
  if (total > timing_.budgetMs()) {
    m.log->write("overrun", time_,
                 {{"frame", frame_}, {"compute_ms", total}, {"stages", timing_.lastCycle()}});
  }
  if (frame_ % 6 == 0)
    m.log->write("cycle", time_,
                 {{"frame", frame_}, {"compute_ms", total}, {"stages", timing_.lastCycle()}});

  // Without an experimenter, a fault or a stop ends the run after a while.
  const bci::Phase phase = paradigm_->phase();
  if (phase == bci::Phase::RobotFault || phase == bci::Phase::EmergencyStop) {
    if (m.fault_since < 0.0) m.fault_since = time_;
    if (options_.start_immediately && time_ - m.fault_since > options_.fault_wait_s) {
      endRun(std::string("stopped waiting for the experimenter after: ") + bci::toString(phase));
    }
  } else {
    m.fault_since = -1.0;
  }
  // The last placement is measured before the run ends (a status after the drop, or 3 s).
  if (phase == bci::Phase::Finished && !robot_->measuring(time_)) {
    endRun("finished");
  }
  if (phase == bci::Phase::Aborted) endRun("aborted");
  if (options_.flashes_only_s > 0.0 && time_ >= options_.flashes_only_s)
    endRun("timing check done");
  if (options_.start_immediately && time_ > options_.max_session_s)
    endRun("the session ran past its time limit");
  if (options_.progress && frame_ % 600 == 0)
    *options_.progress << "\r" << statusLine() << "      " << std::flush;
  ++frame_;
  if (!options_.simulated_clock && m.context.isHeadless()) {
    // --realtime without a display: pace the frames to the wall clock.
    const double wait = m.host_origin + frame_ / config_.display_hz - bci::hostSeconds();
    if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  }
  return !ended_;
}

void Session::collectTraining() {
  if (!eeg_->training()) return;
  // A simulated clock waits for it (the same frame every run); a live cycle looks each frame.
  try {
    const auto outcome = eeg_->trainingResult(options_.simulated_clock);
    if (!outcome) return;
    calibration_report_ = outcome->report;
    eeg_->model()->save(folder_ / "model.json");
    impl_->log->write(
        "trained", time_,
        {{"method", config_.classifier_method},
         {"training_s", time_ - impl_->training_since},
         {"frames_while_training", impl_->frames_while_training},
         {"longest_frame_ms", 1000.0 * impl_->longest_frame_while_training},
         {"median_frame_ms", impl_->stimulus_timing->medianFrameIntervalMs().value_or(0.0)},
         {"auc", calibration_report_->auc},
         {"accuracy_by_sequences", calibration_report_->accuracy}});
    chooseSelectableObjects();
    impl_->last_trial_end = time_;  // the first trial's time counts from here
    paradigm_->modelTrained(true, "");
  } catch (const std::exception& error) {
    impl_->log->write("training_failed", time_, {{"reason", error.what()}});
    paradigm_->modelTrained(false, error.what());
  }
  timing_.mark("training");
}

void Session::presented(double host_s) {
  Impl& m = *impl_;
  if (!m.frame_pending) return;
  m.frame_pending = false;
  const double at = host_s - m.host_origin;
  const std::int64_t sample = eeg_->sampleAt(host_s);
  // What the patch really shows, read back from the frame (a diode would see the same); an
  // unchanged frame shows what the last one did.
  bool patch_lit = m.patch_lit;
  if (eeg_->hasPhotodiode() && m.hmd_redrawn) {
    const int middle = render::HmdFrame::kPatchPx / 2;
    patch_lit = render::readGrey(m.hmd_fbo->id(), m.hmd_fbo->size(), middle, middle) > 127;
  }
  const StimulusTiming::Frame frame =
      m.stimulus_timing->presented(m.due, at, sample, m.lit, m.first_shown);
  if (eeg_->hasPhotodiode() && patch_lit != m.patch_lit) {
    eeg_->displayed(host_s, patch_lit);
    m.patch_lit = patch_lit;
  }
  for (const StimulusTiming::Ended& ended : frame.ended)
    eeg_->flashEnded(ended.onset_sample, ended.duration_samples);
  for (const StimulusTiming::Onset& onset : frame.onsets) eeg_->flash(onset.code, onset.sample);
  if (frame.late) {
    m.log->write("late_frame", at,
                 {{"frame", frame_},
                  {"due_s", m.due},
                  {"late_ms", 1000.0 * (at - m.due)},
                  {"stages", timing_.lastCycle()}});
  }
  if (m.last_presented && eeg_->training()) {
    m.longest_frame_while_training =
        std::max(m.longest_frame_while_training, at - *m.last_presented);
    ++m.frames_while_training;
  }
  m.last_presented = at;
  // Checked once a second or so (it takes a median of the last frame intervals).
  if (!m.warned_slow_display && m.stimulus_timing->framesPresented() % 60 == 0 &&
      m.stimulus_timing->displayTooSlow()) {
    m.warned_slow_display = true;
    const double median = *m.stimulus_timing->medianFrameIntervalMs();
    m.log->write("display_too_slow", at,
                 {{"configured_hz", config_.display_hz},
                  {"median_frame_ms", median},
                  {"text",
                   "the display cannot hold display_hz: flashes are stamped as presented, "
                   "so the recorded SOA and durations are longer than configured"}});
    if (options_.progress)
      *options_.progress << "\nwarning: the display shows a frame every " << median
                         << " ms, not every " << 1000.0 / config_.display_hz
                         << " ms: flash onsets are stamped as presented; the SOA is longer than "
                            "configured\n";
  }
}

std::string Session::timingWarning() const {
  if (!impl_->stimulus_timing->displayTooSlow()) return "";
  char text[160];
  std::snprintf(text, sizeof text, "display too slow: a frame every %.1f ms (configured %.1f ms)",
                *impl_->stimulus_timing->medianFrameIntervalMs(), 1000.0 / config_.display_hz);
  return text;
}

std::string Session::eegClockLine() const {
  char text[160];
  std::snprintf(text, sizeof text, "EEG: lost samples %lld, clock drift %+.1f ppm, jitter %.2f ms",
                static_cast<long long>(eeg_->lostSamples()), eeg_->clockDriftPpm(),
                eeg_->clockJitterMs());
  return text;
}

std::int64_t Session::lateFrames() const {
  return impl_->stimulus_timing->lateFrames();
}

const WorldObjectSettings& Session::objectOfCode(int code) const {
  return config_.world.objects[impl_->slots.at(static_cast<size_t>(code - 1))];
}

void Session::chooseSelectableObjects() {
  Impl& m = *impl_;
  // In view: seen in the last 2 s (an object the robot moved, since it was moved). An object
  // hidden or gone does not flash.
  constexpr double kRecentS = 2.0;
  std::vector<size_t> slots;
  std::vector<int> ids;
  for (size_t i = 0; i < config_.world.objects.size(); ++i) {
    const int id = config_.world.objects[i].id;
    const auto state = vision_->world().object(id);
    if (state && state->age(time_) < kRecentS) {
      slots.push_back(i);
      ids.push_back(id);
    }
  }
  if (slots == m.slots) return;
  if (slots.size() < 2) {
    m.log->write("objects_in_view", time_, {{"objects", ids}, {"kept", "fewer than 2 in view"}});
    return;
  }
  m.slots = slots;
  paradigm_->setObjectCount(static_cast<int>(slots.size()));
  m.log->write("objects_in_view", time_, {{"objects", ids}});
}

std::optional<int> Session::objectOnCell(std::pair<int, int> cell) const {
  const cv::Vec3d centre = gridLayout().cellCentre(cell.first, cell.second);
  const double half = 0.5 * config_.world.grid.cell_m;
  for (const vision::ObjectState& o : vision_->world().objects()) {
    if (robot_->grasped() && o.id == *robot_->grasped()) continue;
    const cv::Vec3d p = o.T_robot_object.translation;
    if (std::abs(p[0] - centre[0]) < half && std::abs(p[1] - centre[1]) < half) return o.id;
  }
  return std::nullopt;
}

render::GridLayout Session::gridLayout() const {
  render::GridLayout grid;
  grid.T_world_grid = {cv::Matx33d::eye(), config_.world.grid.centre};
  grid.rows = config_.world.grid.rows;
  grid.columns = config_.world.grid.columns;
  grid.cell_m = config_.world.grid.cell_m;
  return grid;
}

void Session::handleParadigmEvents() {
  Impl& m = *impl_;
  using Kind = bci::ParadigmEvent::Kind;
  for (const bci::ParadigmEvent& e : paradigm_->takeEvents()) {
    const std::int64_t sample = eeg_->sampleAt(m.host_origin + time_);
    switch (e.kind) {
      case Kind::PhaseChanged: {
        m.log->write("phase", time_,
                     {{"phase", bci::toString(e.phase)}, {"text", e.text}, {"trial", e.trial}});
        eeg_->annotate(sample, "Phase " + e.text);
        const std::string slug = phaseSlug(e.phase);
        if (!slug.empty() && !(e.phase == bci::Phase::CalibrationFlashing &&
                               std::filesystem::exists(folder_ / "hmd_calibration.png"))) {
          m.screenshot_name = e.phase == bci::Phase::CalibrationFlashing ||
                                      e.phase == bci::Phase::Finished ||
                                      e.phase == bci::Phase::RobotFault
                                  ? "hmd_" + slug + ".png"
                                  : "hmd_trial" + std::to_string(e.trial) + "_" + slug + ".png";
          m.screenshot_needs_flash = e.phase == bci::Phase::CalibrationFlashing ||
                                     e.phase == bci::Phase::ObjectFlashing ||
                                     e.phase == bci::Phase::CellFlashing;
        }
        if (options_.progress) *options_.progress << "\r" << statusLine() << "      " << std::flush;
        break;
      }
      case Kind::SelectionStarted: {
        m.selection_flashes = 0;
        m.stimulus_timing->startSelection();
        m.selection_objects = e.objects_layout;
        std::set<int> attended;
        std::optional<int> target;
        if (paradigm_->phase() == bci::Phase::CalibrationCue ||
            paradigm_->phase() == bci::Phase::CalibrationFlashing) {
          attended = e.codes;
          target = *e.codes.begin();
          m.log->write("calibration_target", time_, {{"object", objectOfCode(*target).id}});
        } else {
          const TrialRecord& trial = currentTrial();
          if (e.objects_layout) {
            for (size_t k = 0; k < m.slots.size(); ++k) {
              if (config_.world.objects[m.slots[k]].id == trial.intended_object)
                attended = {static_cast<int>(k) + 1};
            }
            if (attended.empty()) {
              std::cerr << "trial " << trial.trial << ": the intended object "
                        << trial.intended_object << " is not in view, so it does not flash\n";
              m.log->write("intended_not_in_view", time_,
                           {{"trial", trial.trial}, {"object", trial.intended_object}});
            }
          } else {
            attended = {trial.intended_cell.first,
                        config_.world.grid.rows + trial.intended_cell.second};
          }
        }
        eeg_->startSelection(e.objects_layout,
                             e.objects_layout ? paradigm_->objectLayout() : paradigm_->gridLayout(),
                             attended, target);
        break;
      }
      case Kind::Flash:
        // Stamped when the frame that shows it is presented.
        m.first_shown.push_back(e.code);
        ++m.selection_flashes;
        break;
      case Kind::SelectionMade: {
        TrialRecord& trial = currentTrial();
        if (e.objects_layout) {
          trial.selected_object = objectOfCode(e.object).id;
          trial.object_certainty = e.certainty;
          trial.object_flashes = m.selection_flashes;
          trial.object_selection_s = m.stimulus_timing->selectionSeconds();
        } else {
          trial.selected_cell = e.cell;
          trial.cell_certainty = e.certainty;
          trial.cell_flashes = m.selection_flashes;
          trial.cell_selection_s = m.stimulus_timing->selectionSeconds();
        }
        const bool correct = e.objects_layout ? trial.selected_object == trial.intended_object
                                              : trial.selected_cell == trial.intended_cell;
        nlohmann::json fields = {{"trial", trial.trial},
                                 {"kind", e.objects_layout ? "object" : "cell"},
                                 {"certainty", e.certainty},
                                 {"flashes", m.selection_flashes},
                                 {"correct", correct}};
        if (e.objects_layout) {
          fields["selected"] = trial.selected_object;
          fields["intended"] = trial.intended_object;
        } else {
          fields["selected"] = {e.cell.first, e.cell.second};
          fields["intended"] = {trial.intended_cell.first, trial.intended_cell.second};
        }
        m.log->write("selection", time_, fields);
        eeg_->annotate(sample,
                       std::string("Selected ") +
                           (e.objects_layout ? "object " + std::to_string(trial.selected_object)
                                             : "cell " + std::to_string(e.cell.first) + "," +
                                                   std::to_string(e.cell.second)) +
                           (correct ? " (intended)" : " (not the intended)"));
        if (!correct && options_.progress) {
          *options_.progress << "\nselection "
                             << (e.objects_layout ? "of the object" : "of the cell") << " in trial "
                             << trial.trial << " differs from the intended one; carrying on\n";
        }
        break;
      }
      case Kind::TrainModel:
        // On a worker thread: the cycle (and the window) goes on; collectTraining() takes it.
        eeg_->startTraining(config_.classifier_method);
        m.training_since = time_;
        m.log->write("training_started", time_, {{"method", config_.classifier_method}});
        break;
      case Kind::RobotGrasp: {
        const int id = objectOfCode(e.object).id;
        const auto state = vision_->world().object(id);
        if (!state) {
          // Never a grasp at a stale position: a moved object is grasped once seen again.
          currentTrial().outcome = "object " + std::to_string(id) +
                                   " is not in view (never seen, or not since the robot moved it)";
          paradigm_->robotFinished(false, currentTrial().outcome);
          break;
        }
        robot_->grasp(id, state->T_robot_object.translation, time_);
        break;
      }
      case Kind::RobotDrop: {
        const auto other = objectOnCell(e.cell);
        if (other) {
          // Never onto another object: it goes back where it came from, and the trial says why.
          currentTrial().outcome = "returned: cell " + std::to_string(e.cell.first) + "," +
                                   std::to_string(e.cell.second) + " is taken by object " +
                                   std::to_string(*other);
          std::cerr << "trial " << currentTrial().trial << ": " << currentTrial().outcome << "\n";
        }
        robot_->drop(e.cell, other.has_value(), time_);
        break;
      }
      case Kind::RobotStop:
        robot_->stop(time_);
        break;
      case Kind::TrialDone:
        if (e.trial >= 1 && e.trial <= static_cast<int>(trials_.size()))
          trials_[static_cast<size_t>(e.trial - 1)].ended_s = time_;
        m.last_trial_end = time_;
        m.log->write("trial_done", time_, {{"trial", e.trial}});
        break;
    }
  }
}

void Session::decideIfReady() {
  const bci::Phase phase = paradigm_->phase();
  const bool online = phase == bci::Phase::ObjectFlashing || phase == bci::Phase::CellFlashing;
  // Dynamic stopping: certain enough after the minimum number of scored sequences.
  if (online && eeg_->hasModel() && config_.paradigm.certainty > 0.0 &&
      eeg_->scoredSequences() >= config_.paradigm.min_sequences &&
      eeg_->decide().certainty >= config_.paradigm.certainty) {
    paradigm_->requestStopFlashing();
  }
  if (paradigm_->awaitingDecision() && eeg_->selectionScored()) paradigm_->decide(eeg_->decide());
}

void Session::renderHmd(const bci::FrameStimulus& stimulus) {
  Impl& m = *impl_;
  const HmdScene scene{config_,      *vision_,
                       m.slots,      robot_->status() ? robot_->status()->holding : -1,
                       gridLayout(), eeg_->hasPhotodiode()};
  const render::HmdFrame frame = composeHmdFrame(stimulus, scene);
  // What this frame shows; unchanged, the framebuffer already holds it.
  const std::string signature = hmdFrameSignature(frame);
  m.hmd_redrawn = signature != m.last_hmd_signature;
  if (m.hmd_redrawn) {
    m.hmd->draw(frame, m.hmd_fbo->id(), m.hmd_fbo->size());
    m.last_hmd_signature = signature;
  }
  if (m.screenshot_name && (!m.screenshot_needs_flash || !stimulus.lit.empty())) {
    screenshot(folder_ / *m.screenshot_name);
    m.screenshot_name.reset();
  }
}

unsigned int Session::hmdTexture() const {
  return impl_->hmd_fbo->colorTexture();
}

void Session::setThreshold(const vision::ThresholdSettings& settings) {
  vision_->detector().setThreshold(settings);
}

void Session::setReference(int id, const cv::Vec3d& position) {
  vision_->setReference(id, config_.world.reference_size_m, position);
  impl_->log->write("reference", time_,
                    {{"id", id}, {"position", {position[0], position[1], position[2]}}});
}

bool Session::canHoldBoard() const {
  return impl_->scene->canHoldBoard();
}

void Session::holdBoard(bool show) {
  impl_->scene->holdBoard(show, time_);
}

void Session::useModel(const bci::P300Model& model) {
  eeg_->setModel(model);
  impl_->log->write("model", time_, {{"method", model.method}, {"provenance", model.provenance}});
}

std::vector<std::string> Session::selectionLines() const {
  std::vector<std::string> lines;
  for (const TrialRecord& t : trials_) lines.push_back(selectionLine(t));
  return lines;
}

void Session::screenshot(const std::filesystem::path& path) {
  const render::RgbaImage image = render::readPixels(impl_->hmd_fbo->id(), impl_->hmd_fbo->size());
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  impl_->images.write(path, bgr);
}

std::string Session::statusLine() const {
  char text[256];
  std::snprintf(text, sizeof text,
                "t=%.1f s  trial %d/%d  %s  cycle p50 %.1f ms  overruns %d  late frames %lld",
                time_, std::max(paradigm_->trial(), 0), config_.paradigm.trials,
                bci::toString(paradigm_->phase()), timing_.totalPercentiles().p50,
                timing_.overruns(), static_cast<long long>(lateFrames()));
  const std::string warning = timingWarning();
  return warning.empty() ? std::string(text) : std::string(text) + "  [" + warning + "]";
}

void Session::endRun(const std::string& reason) {
  if (ended_) return;
  ended_ = true;
  end_reason_ = reason;
  Impl& m = *impl_;
  // Live: the EEG of the last frames (their flashes' responses begin later) is still on its way.
  if (!options_.simulated_clock) eeg_->drainUntil(bci::hostSeconds() + 0.1, 1.0);
  eeg_->annotate(eeg_->sampleAt(m.host_origin + time_), "Session ended: " + reason);
  eeg_->close();
  m.images.flush();
  m.log->write("session_ended", time_, {{"reason", reason}});
  std::ofstream(folder_ / "summary.json") << summary().dump(2) << "\n";
  if (options_.progress)
    *options_.progress << "\r" << statusLine() << "\nsession ended: " << reason << "\n";
}

nlohmann::json Session::summary() const {
  nlohmann::json out = {
      {"session", config_.source},
      {"seed", config_.eeg.seed},
      {"ended", end_reason_},
      {"duration_s", time_},
      {"frames", frame_},
      {"cycle", timing_.toJson()},
      {"overruns", timing_.overruns()},
      {"timing", impl_->stimulus_timing->summary(eeg_->lostSamples(), eeg_->clockDriftPpm(),
                                                 eeg_->clockJitterMs())},
      {"eeg",
       {{"recording", "recording.bdf"},
        {"samples", eeg_->samplesRecorded()},
        {"lost_samples", eeg_->lostSamples()},
        {"missed_epochs", eeg_->missedEpochs()}}},
  };
  out.update(trialsSummary(trials_, static_cast<int>(config_.world.objects.size()),
                           config_.world.grid.rows * config_.world.grid.columns));
  if (calibration_report_) {
    out["calibration"] = {{"selections", calibration_report_->selections.size()},
                          {"auc", calibration_report_->auc},
                          {"accuracy_by_sequences", calibration_report_->accuracy}};
  }
  return out;
}

nlohmann::json Session::run() {
  while (step()) {
    if (interruptRequested()) abort();  // ends at the next frame, its summary saved
  }
  return summary();
}

}  // namespace arbci::app
