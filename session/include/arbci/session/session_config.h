// A session file (JSON): the display, the cameras, the tracker, the world (reference marker,
// objects, grid), the EEG source, the paradigm, the classifier, error-related potentials and the
// robot. Every key, its type, what it allows, its default and what it means is in the settings
// schema (settings_schema.h; docs/settings.md is generated from it): a file names only what
// differs, and loading checks everything once, naming the key, the value and what is allowed.
// The structs below carry no defaults of their own: their constructors take the schema's.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core/matx.hpp>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"
#include "arbci/bci/lsl/config.h"
#include "arbci/bci/paradigm.h"
#include "arbci/bci/signal_quality.h"
#include "arbci/vision/marker_detector.h"

namespace arbci::session {

class SessionConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct HmdConfig {
  HmdConfig();
  int width, height;  // both eyes side by side
  bool undistort;
  int mirror_monitor;       // -1: no mirror window
  std::string output;       // where the subject's view goes: "window" or "openxr"
  std::string screenshots;  // which HMD frames are kept: "phases", "first_trial", "end", "none"
};

struct CameraSource {
  CameraSource();
  int device;               // V4L2 index, or
  std::string video;        // a video file
  std::string calibration;  // its calibration file (OpenCV YAML/XML)
  bool used() const { return device >= 0 || !video.empty() || !calibration.empty(); }
};

struct CameraSettings {
  CameraSettings();
  std::string source;  // a name of sceneSources()
  double rate_hz;
  // Simulated cameras.
  int width, height;
  double focal_px;
  std::vector<double> distortion;
  double baseline_m;
  cv::Vec3d head_position;
  cv::Vec3d look_at;
  double head_motion_m, head_motion_deg;
  double noise, blur_px;
  // Real cameras.
  CameraSource left, right;        // right unused: mono (the left feeds both eyes)
  std::string stereo_calibration;  // optional: the right camera's pose in the left's frame
};

struct TrackerSettings {
  TrackerSettings();
  vision::DetectorConfig detector;  // kind, border and search_decimate are settings
  // A pose older than this is stale: its object is not flashed, offered or grasped, and the
  // panels say "tracking lost" (also for the reference marker).
  double max_pose_age_s;
};

struct WorldObjectSettings {
  WorldObjectSettings();
  int id;              // its marker's BCH id
  cv::Vec3d position;  // top centre, robot frame
  double marker_m, width_m, height_m;
  double mass_kg, friction;  // the physics driver's body
  cv::Vec3d color;
  // Simulated cameras: a hand lies over its marker between each pair of session times (from, to).
  std::vector<double> covered_s;
};

struct GridSettings {
  GridSettings();
  int rows, columns;
  double cell_m;
  cv::Vec3d centre;  // robot frame, on the table
  // The centre of cell (row, column), 1-based, on the table in the robot frame: rows run along
  // -y from the far edge, columns along +x.
  cv::Vec3d cellCentre(int row, int column) const {
    const double x = (column - 0.5 - columns / 2.0) * cell_m;
    const double y = (rows / 2.0 - (row - 0.5)) * cell_m;
    return {x + centre[0], y + centre[1], 0.0 + centre[2]};
  }
};

struct WorldSettings {
  WorldSettings();
  double table_z;
  int reference_id;
  double reference_size_m;
  cv::Vec3d reference_position;
  std::vector<WorldObjectSettings> objects;
  GridSettings grid;
};

struct EegSettings {
  EegSettings();
  std::string source;  // a name of eegSources()
  std::uint64_t seed;
  std::vector<std::string> montage;
  double rate_hz;
  int block_size;
  double line_hz;
  double erp_scale;   // the simulated subject's ERP amplitude factor (weak subjects < 1)
  double errp_scale;  // its error-related potentials' amplitude factor (0: none)
  std::string file;   // source "file": a recording replayed in real time
  // The channel a photodiode on the HMD's patch feeds (simulated: a virtual channel of this name
  // is added); empty: none.
  std::string photodiode_channel;
  // An amplifier that marks the photodiode through a trigger input (BrainVision's RDA sends it as
  // a marker): the marker as recorded ("Stimulus/S  1"), whose onsets the timing check takes as
  // the diode's edges; empty: none.
  std::string photodiode_marker;
  double latency_ms;  // the amplifier's delivery latency, as timing-check measured it
  // What the recording says of the amplifier (a BIDS export's EEGReference and Manufacturer).
  std::string reference, manufacturer;
  // Each source's own section (eeg.lsl, eeg.eegdev, eeg.rda, ...), resolved by its schema.
  std::map<std::string, nlohmann::json> sources;
  // A trigger written to the amplifier at each flash's presentation: "none" or "serial"; the
  // port's section (eeg.trigger: device, baud, bytes), resolved by triggerSchema()
  // (session/trigger_output.h).
  std::string trigger_out;
  nlohmann::json trigger;
  // A source that runs on its own clock in real time (an amplifier): the session cannot step it.
  bool live() const;
};

// The Lab Streaming Layer (docs/eeg.md): where streams are looked for and what ARBCI publishes.
// The scope and peers default to the lab's lsl_api.cfg (read as liblsl reads it).
struct LslSettings {
  LslSettings();
  std::string scope;                     // "" (from lsl_api.cfg), "machine", "link" or "site"
  std::vector<std::string> known_peers;  // added to lsl_api.cfg's KnownPeers
  bool markers;                          // publish every stimulus and event as a Markers stream
  std::string marker_stream;
  // lsl_api.cfg (throws SessionConfigError for one that does not parse) with this file's scope
  // and peers over it.
  bci::lsl::LslConfig config(const std::string& session_file) const;
};

// The P300 classifier the calibration run trains (or the model it uses instead).
struct ClassifierSettings {
  bci::PipelineSettings pipeline;
  bci::TrainingSettings training;
  std::string model_file;  // a trained model: no calibration run
};

// The ErrP classifier (docs/errp.md), trained on the calibration run's feedback block when
// errp.enabled is on: by default the Riemannian method with one xDAWN filter per class over all
// the montage's channels (the filter finds the fronto-central response and cancels what the
// channels share), 0-800 ms after each feedback, band-passed on its own (1-10 Hz, as ErrP studies
// filter; the P300's filters stay the P300's). Shrinkage LDA on the fronto-central channels is
// the literature's baseline: {"method": "slda", "channels": ["FCz", "Fz", "Cz", "FC1", "FC2"]}.
struct ErrpSettings {
  ErrpSettings();
  double threshold;  // a selection whose posterior of "error" exceeds it is rejected
  std::vector<std::string> channels;  // empty: all of the montage's
  bci::EpochWindow window;
  double decimate_hz;
  double highpass_hz, lowpass_hz;
  std::string method;
  int xdawn_filters;  // xDAWN: filters kept; riemann: per class
  int folds;          // contiguous blocks of the feedbacks, for its cross-validation
  // The ErrP pipeline: the session's notch, these band edges, window, decimation and channels
  // (those of `channels` the montage has, or the whole montage; throws SessionConfigError when it
  // has none of them).
  bci::PipelineSettings pipeline(const bci::PipelineSettings& p300,
                                 const std::vector<std::string>& montage) const;
  // How it is trained and cross-validated: the method, its filters, the folds by block (the
  // feedbacks are two classes, not selections). The session and `arbci train --errp` both use it.
  bci::TrainingSettings training() const;
};

struct TrialIntent {
  TrialIntent();
  int object;  // marker id
  int row, column;
};

struct RobotSettings {
  RobotSettings();
  std::string backend;  // "simulated" (arbci-robotd here) or "remote"
  std::string driver;   // simulated: the arm arbci-robotd drives (robot::robotDrivers())
  std::string model;    // simulated, mujoco driver: its arm's MJCF (robot::RobotConfig::model)
  double speed_factor;  // the simulated arm's
  std::string host;
  int port;
  int watchdog_ms;  // simulated: the arbci-robotd started here halts after this much silence
  std::string key_file;
};

// The gates a run passes (docs/session.md, "Gates"): the signal's quality at Start, the
// calibration's review before the first online trial, and the flashes' timing during the run.
struct GateSettings {
  GateSettings();
  std::string signal_quality;  // "ask", "refuse" or "off"
  int bad_channels_allowed;
  double flat_sd_uv, line_bad_uv, drift_bad_uv_s, rms_bad_uv;  // a channel graded bad
  bool review;         // windowed: the experimenter accepts the calibration before going online
  double min_auc;      // below it the session does not go online unattended (0: no minimum)
  int max_retakes;     // calibration selections retaken before the experimenter is asked
  std::string timing;  // "pause", "annotate" or "off"
  double max_flash_ms, min_gap_ms, min_soa_ms;  // 0: derived from the paradigm's settings
  double max_off_share;                         // of a selection's flashes, then it pauses
  double max_late_share;                        // of the last 120 frames, then it pauses
  // How a channel is graded, at Start and in the EEG panel alike; `line_hz`: the notch's.
  bci::QualityThresholds thresholds(double line_hz) const;
};

struct SessionConfig {
  SessionConfig();                          // the schema's defaults: the embedded simulated session
  std::string source = "embedded default";  // the file it was read from (not a setting)
  std::string description;
  HmdConfig hmd;
  CameraSettings cameras;
  TrackerSettings tracker;
  WorldSettings world;
  EegSettings eeg;
  LslSettings lsl;
  bci::ParadigmSettings paradigm;  // display_hz (the file's root key) among them
  std::vector<TrialIntent> intended;
  ClassifierSettings classifier;
  ErrpSettings errp;
  RobotSettings robot;
  GateSettings gates;

  double displayHz() const { return paradigm.display_hz; }
  // No calibration run and no model: the classifier learns from the trials (paradigm.calibration
  // "none"; a model file given is used instead, as with "cued").
  bool learnsFromUse() const {
    return paradigm.calibration == "none" && classifier.model_file.empty();
  }
  // The defaults, or `path` over the defaults. Throws SessionConfigError naming the key.
  static SessionConfig load(const std::optional<std::filesystem::path>& path);
  // `json` (a session file's content) over the defaults; `name` for messages.
  static SessionConfig parse(const nlohmann::json& json, const std::string& name);
  // Every key with the value this session uses.
  nlohmann::json toJson() const;
};

}  // namespace arbci::session
