// A session file (JSON): the display, the cameras, the tracker, the world (reference marker,
// objects, grid), the EEG source, the paradigm, the classifier and the robot. Every key has a
// default (the embedded simulated session, assets/sessions/simulated.json); a file names only what
// differs. Loading validates everything once and names the key, the value and what is allowed.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/matx.hpp>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"
#include "arbci/bci/lsl/config.h"
#include "arbci/bci/paradigm.h"

namespace arbci::session {

class SessionConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CameraSource {
  int device = -1;          // V4L2 index, or
  std::string video;        // a video file
  std::string calibration;  // its calibration file (OpenCV YAML/XML)
};

struct CameraSettings {
  std::string source = "simulated";  // "simulated" or "devices"
  double rate_hz = 30.0;
  // Simulated cameras.
  int width = 640, height = 480;
  double focal_px = 800.0;
  std::vector<double> distortion;
  double baseline_m = 0.064;
  cv::Vec3d head_position{0.0, 1.20, 0.75};
  cv::Vec3d look_at{0.0, 0.70, 0.0};
  double head_motion_m = 0.008, head_motion_deg = 0.6;
  double noise = 2.0, blur_px = 0.5;
  // Real cameras.
  CameraSource left, right;        // right.device < 0 and right.video empty: mono (feeds both eyes)
  std::string stereo_calibration;  // optional: the right camera's pose in the left's frame
};

struct WorldObjectSettings {
  int id = 0;          // its marker's BCH id
  cv::Vec3d position;  // top centre, robot frame
  double marker_m = 0.05, width_m = 0.07, height_m = 0.06;
  cv::Vec3d color{0.8, 0.4, 0.3};
};

struct GridSettings {
  int rows = 3, columns = 3;
  double cell_m = 0.09;
  cv::Vec3d centre{0.0, 0.66, 0.0};  // robot frame, on the table
  // The centre of cell (row, column), 1-based, on the table in the robot frame: rows run along
  // -y from the far edge, columns along +x.
  cv::Vec3d cellCentre(int row, int column) const {
    const double x = (column - 0.5 - columns / 2.0) * cell_m;
    const double y = (rows / 2.0 - (row - 0.5)) * cell_m;
    return {x + centre[0], y + centre[1], 0.0 + centre[2]};
  }
};

struct WorldSettings {
  double table_z = 0.0;
  int reference_id = 0;
  double reference_size_m = 0.08;
  cv::Vec3d reference_position{0.0, 0.90, 0.0};
  std::vector<WorldObjectSettings> objects;
  GridSettings grid;
};

struct EegSettings {
  std::string source = "simulated";  // "simulated", "file", "lsl" or "eegdev"
  std::uint64_t seed = 1;
  std::vector<std::string> montage{"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"};
  double rate_hz = 256.0;
  int block_size = 15;
  double line_hz = 50.0;
  double erp_scale = 1.0;   // the simulated subject's ERP amplitude factor (weak subjects < 1)
  double errp_scale = 1.0;  // its error-related potentials' amplitude factor (0: none)
  std::string file;         // source "file": a recording replayed in real time
  // The channel a photodiode on the HMD's patch feeds (simulated: a virtual channel of this name
  // is added); empty: none.
  std::string photodiode_channel;
  double latency_ms = 0.0;  // the amplifier's delivery latency, as timing-check measured it
  // source "lsl": the stream, by name and/or type, and how long to look for it.
  std::string lsl_name;
  std::string lsl_type = "EEG";
  double lsl_resolve_timeout_s = 5.0;
  // source "eegdev": eegdev's device string (device|option|value..., e.g. "biosemi",
  // "datafile|path|/data/s01.bdf").
  std::string eegdev_device;
  // A source that runs on its own clock in real time (an amplifier): the session cannot step it.
  bool live() const { return source == "lsl" || source == "eegdev"; }
};

// The Lab Streaming Layer (docs/eeg.md): where streams are looked for and what ARBCI publishes.
// The scope and peers default to the lab's lsl_api.cfg (read as liblsl reads it).
struct LslSettings {
  std::string scope;                     // "" (from lsl_api.cfg), "machine", "link" or "site"
  std::vector<std::string> known_peers;  // added to lsl_api.cfg's KnownPeers
  bool markers = false;                  // publish every stimulus and event as a Markers stream
  std::string marker_stream = "ARBCI-Markers";
  // lsl_api.cfg (throws SessionConfigError for one that does not parse) with this file's scope
  // and peers over it.
  bci::lsl::LslConfig config(const std::string& session_file) const;
};

// The ErrP classifier (docs/errp.md), trained on the calibration run's feedback block when
// paradigm.errp is on: by default the Riemannian method with one xDAWN filter per class over all
// the montage's channels (the filter finds the fronto-central response and cancels what the
// channels share), 0-800 ms after each feedback, band-passed on its own (1-10 Hz, as ErrP studies
// filter; the P300's filters stay the P300's). Shrinkage LDA on the fronto-central channels is
// the literature's baseline: {"method": "slda", "channels": ["FCz", "Fz", "Cz", "FC1", "FC2"]}.
struct ErrpSettings {
  double threshold = 0.5;  // a selection whose posterior of "error" exceeds it is rejected
  std::vector<std::string> channels;  // empty: all of the montage's
  bci::EpochWindow window{0.0, 0.8};
  double decimate_hz = 20.0;
  double highpass_hz = 1.0, lowpass_hz = 10.0;
  std::string method = "riemann";
  int xdawn_filters = 1;  // xDAWN: filters kept; riemann: per class
  // The ErrP pipeline: the session's notch, these band edges, window, decimation and channels
  // (those of `channels` the montage has, or the whole montage; throws SessionConfigError when it
  // has none of them).
  bci::PipelineSettings pipeline(const bci::PipelineSettings& p300,
                                 const std::vector<std::string>& montage) const;
  // How it is trained and cross-validated: the method, its filters, 5 contiguous blocks (the
  // feedbacks are two classes, not selections). The session and `arbci train --errp` both use it.
  bci::TrainingSettings training() const;
};

struct TrialIntent {
  int object = 0;  // marker id
  int row = 1, column = 1;
};

struct SessionConfig {
  std::string source = "embedded default";
  double display_hz = 60.0;
  int hmd_width = 1280, hmd_height = 480;
  bool undistort = true;
  int mirror_monitor = -1;
  CameraSettings cameras;
  std::string tracker_kind = "bch";
  double tracker_border = 0.125;
  // 1: markers are searched at full resolution; 2: on the frame averaged over 2x2 pixels, corners
  // refined at full resolution (faster; markers need about 24 px per side; docs/tracker.md).
  int tracker_search_decimate = 1;
  // A pose older than this is stale: its object is not flashed, offered or grasped, and the
  // panels say "tracking lost" (also for the reference marker).
  double max_pose_age_s = 0.5;
  WorldSettings world;
  EegSettings eeg;
  LslSettings lsl;
  bci::ParadigmSettings paradigm;
  std::vector<TrialIntent> intended;
  std::string classifier_method = "slda";
  bci::PipelineSettings pipeline;
  ErrpSettings errp;
  std::string model_file;                   // a trained model: no calibration run
  std::string robot_backend = "simulated";  // "simulated" (arbci-robotd here) or "remote"
  double robot_speed_factor = 8.0;
  std::string robot_host = "127.0.0.1";
  int robot_port = 47800;
  std::string robot_key_file;

  // The embedded default, or `path` over the defaults. Throws SessionConfigError.
  static SessionConfig load(const std::optional<std::filesystem::path>& path);
  // The defaults from a session file's text that must set every key (the embedded one is
  // assets/sessions/simulated.json): the one place a default lives. Throws SessionConfigError
  // naming a key it lacks.
  static SessionConfig defaults(const std::string& json_text, const std::string& name);
};

}  // namespace arbci::session
