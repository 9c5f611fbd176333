// One cycle of the session (one displayed frame) and the record of what it produced. Stages are
// peers on this record: each reads what earlier stages wrote this cycle (and, for what flows back
// against the stage order, what later stages wrote last cycle: `previous`), and writes only its
// own part. docs/architecture.md lists who writes each field.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

#include <nlohmann/json.hpp>

#include "arbci/bci/acquisition.h"
#include "arbci/bci/decision.h"
#include "arbci/bci/erp.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/paradigm.h"
#include "arbci/bci/signal.h"
#include "arbci/bci/signal_quality.h"
#include "arbci/core/run_labels.h"
#include "arbci/robot/protocol.h"
#include "arbci/session/clock.h"
#include "arbci/session/requests.h"
#include "arbci/session/trial_record.h"
#include "arbci/vision/camera_model.h"
#include "arbci/vision/marker.h"
#include "arbci/vision/pose.h"
#include "arbci/vision/world_model.h"

namespace arbci::session {

// A flash the paradigm shows for the first time on a frame, labelled by what the subject attends:
// T (target), N, or U when the attended codes are not known.
struct Flash {
  int code = 0;
  bool objects = true;  // an object's code, else a grid row's or column's (recorded as 100 + code)
  bool target = false;
  bool known = true;
  int selection = 0;  // the paradigm's selection it belongs to
};

// A selection's feedback shown for the first time.
struct FeedbackShown {
  std::set<int> codes;
  bool objects = true;
  std::optional<bool> error;  // known: the calibration block's, or against the intention
  // "Feedback 3 error" (grid codes as 100 + code, several joined by '+'): its note in the
  // recording and on the Markers stream.
  std::string text() const;
};

// A new selection's stimuli and what the subject attends.
struct SelectionStart {
  int selection = 0;
  bool objects = true;
  bci::ParadigmLayout layout;
  std::set<int> attended;     // the simulated subject looks there; empty: not known
  std::optional<int> target;  // the calibration run's cued code
  // A calibration selection interrupted and cued again: the number of the one it replaces,
  // whose flashes are no whole selection and are left out of training.
  std::optional<int> retake_of;
  int trial = 0;  // online: the trial it belongs to (0: a calibration selection)
};

// The last frame as the screen showed it, stamped on the EEG sample clock once presented.
struct Presentation {
  bool shown = false;       // a frame was presented since the last cycle
  double host_s = 0.0;      // when it reached the screen (host clock)
  double at_s = 0.0;        // the same in session seconds
  std::int64_t sample = 0;  // the first EEG sample taken at or after it
  std::int64_t frame = 0;
  struct Onset {
    Flash flash;
    std::int64_t sample = 0;
  };
  std::vector<Onset> onsets;  // flashes whose first frame it was
  struct Ended {
    std::int64_t onset_sample = 0;
    int duration_samples = 0;
  };
  std::vector<Ended> ended;  // flashes it no longer showed
  std::optional<FeedbackShown> feedback;
  std::optional<bool> patch;  // the photodiode patch changed to lit (true) or dark on this frame
  bool late = false;
  // The current selection's duration from its onsets as presented (first to last, plus one SOA),
  // without the time it spent interrupted (paused, E-STOP, robot fault), which is apart.
  double selection_s = 0.0;
  double selection_interrupted_s = 0.0;
  std::optional<double> median_frame_ms;  // once 60 frames were presented
  std::int64_t late_frames = 0;
  bool display_too_slow = false;
};

struct EegPart {
  std::shared_ptr<const bci::SignalInfo> info;  // every channel as acquired (names, rate)
  std::vector<bci::Block> blocks;               // as acquired: every channel (the photodiode too)
  std::vector<bci::Block> eeg_blocks;  // the EEG channels only (filters, epochs, classifiers)
  std::vector<bci::SampleLoss> losses;
  std::string fault;        // why a live source delivers nothing now; empty while it does
  std::string source_line;  // the source's own account (an LSL stream's name, host, rates)
  std::string impedance;    // the electrodes' impedances where the source reports them
  std::int64_t lost_samples = 0;
  double drift_ppm = 0.0, jitter_ms = 0.0;
  bool drift_reliable = false;             // see bci::ClockModel::driftReliable
  std::vector<bci::DeliveryStall> stalls;  // deliveries held up, taken this cycle
};

// Each EEG channel's quality over the last 2 s of raw signal, graded as the EEG panel grades it
// (the quality gate at Start reads it; signal_quality_stage.h).
struct QualityPart {
  std::vector<std::string> channels;
  std::vector<bci::SignalQuality> quality;  // one per channel; empty until 2 s were seen
  // "C3: flat: SD 0.10 uV (bad below 0.5)" for each channel graded bad.
  std::vector<std::string> bad() const;
  nlohmann::json toJson() const;  // [{channel, grade, finding, rms_uv, ...}]
};

struct RecordingPart {
  std::int64_t samples = 0;  // written so far
};

// Learning from use (paradigm.calibration none, or paradigm.adapt): the last fit over the
// object selections so far (bci/learning_from_use.h).
struct LearningState {
  bool adapting = false;    // a calibrated model adapted (else one learnt from nothing)
  bool trusted = false;     // the arm may act on the model (always, when adapting)
  std::string waiting_for;  // what trust waits for, in words
  int fits = 0;
  int selections = 0;  // object selections the last fit learnt from
  int agreeing = 0, restarts = 0;
  double consistency = 0.0;              // held out (bci/unsupervised.h)
  int beats_shuffled = 0, shuffles = 0;  // fits with shuffled codes the fit explains more than
  std::map<int, int> post_hoc;  // selection number -> the code the last fit decoded (1-based)
  std::map<int, int> frozen;    // adapting: the code the calibrated model decodes
  std::vector<int> changed;     // selections whose decoding the last fit changed
  bool fitting = false;         // a fit is running on its worker thread
  // Selection numbers: the last fit taken (or failed) learnt from those up to `fitted_through`;
  // one learning from those up to `awaited_through` is running or about to start.
  int fitted_through = 0, awaited_through = 0;
  std::string error;  // why the last fit failed (the model before it is kept)
  // "learning: 3 selections, not yet moving the arm; waiting for: 2 more selections".
  std::string line() const;
};

struct P300Part {
  int selection = 0;  // the selection the counts and the decision belong to
  int presented = 0, scored = 0;
  int sequences = 0;  // complete sequences scored
  bci::Decision decision;
  // The score model the decision's evidence is weighed under (the model's, its separation held
  // to what the online selections of its kind showed), and that separation when it was known.
  bci::ScoreModel scored_by;
  std::optional<double> held_out_separation;
  std::shared_ptr<const bci::P300Model> model;  // none before training (or a model file)
  std::shared_ptr<const bci::ErpCurves> erp;    // the averages this session trained on
  // Training ended this cycle: the model's cross-validation, or why it failed.
  std::optional<bci::EvaluationReport> trained;
  std::string training_error;
  // With `trained`: the calibration selections (the paradigm's numbers) it was trained on, and
  // those left out because they were interrupted and retaken.
  std::vector<int> trained_on, left_out;
  bool training = false;                          // on its worker thread
  std::shared_ptr<const LearningState> learning;  // none unless the session learns from use
};

struct ErrpPart {
  std::shared_ptr<const bci::P300Model> model;  // the ErrP classifier, once there is one
  double auc = 0.0;                             // its cross-validated AUC (NaN: not known)
  std::shared_ptr<const bci::ErpCurves> erp;
  // The score of a feedback epoch completed this cycle: {feedback onset sample, score}.
  std::optional<std::pair<std::int64_t, double>> score;
  std::optional<bci::EvaluationReport> trained;  // training ended this cycle
  std::string training_error;
  bool training = false;
  bool enabled = false;  // the session trains and uses one
};

struct CameraPart {
  cv::Mat left;                 // a new left frame (empty: none this cycle)
  bool left_changed = true;     // false: the same picture as the last left frame
  cv::Mat right;                // a new right frame (empty: none this cycle)
  bool can_hold_board = false;  // a simulated scene can hold a chessboard up
  bool any() const { return !left.empty() || !right.empty(); }
};

// What tracking knows after this cycle's frames (the world in the robot's frame).
struct TrackingPart {
  cv::Mat left_image, right_image;  // the latest frames (right: the left one when mono)
  bool stereo = false;
  vision::CameraModel left_camera, right_camera;
  std::optional<vision::Pose> T_cam_world_left, T_cam_world_right;
  vision::DetectionResult detection;    // of the latest left frame
  cv::Mat binary;                       // the tracker's binary image of it
  vision::ThresholdSettings threshold;  // how the tracker thresholds (the experimenter's last)
  std::shared_ptr<const vision::WorldModel> world;
  // The tracking stage publishes tracker.max_pose_age_s here; until it does (0) every pose is
  // stale, so a record built by hand says how old a pose may be.
  double max_pose_age_s = 0.0;
  // The object's pose is known and no older than the allowed age at `now_s`.
  bool fresh(int id, double now_s) const;
  // "" while the reference and every object in `ids` are fresh, else "tracking lost: reference
  // 0 (2.1 s), object 40 (never seen)".
  std::string alarm(const std::vector<int>& ids, double now_s) const;
};

struct RobotPart {
  std::optional<robot::StatusPayload> status;
  bool silent = false;
  bool busy = false;           // a trial's or the experimenter's command is running
  bool at_home = true;         // HOME finished since the last motion
  bool measuring = false;      // a placement still to be measured
  std::optional<int> grasped;  // the object the arm was sent to grasp in this session
  bool answered = false;       // the backend answered the last probe
  bool key_refused = false;    // the backend answered that our key is not its key
  std::string why_not_move, why_not_release;                 // "" when the experimenter may
  std::shared_ptr<const std::vector<std::string>> messages;  // for the Robot panel
  // This cycle: what the trial's robot step came to, in the order it happened.
  struct Note {
    enum class Kind { Outcome, Placement, Finished, PutDownEnded } kind;
    bool success = true;
    std::string text;
    int trial = 0;  // Placement
    double error_m = 0.0;
  };
  std::vector<Note> notes;
  std::vector<int> moved;  // objects the robot moved: their poses are unknown until seen again
  std::optional<int> holding() const {
    if (!status || status->holding < 0) return std::nullopt;
    return status->holding;
  }
};

struct PhaseChange {
  bci::Phase phase;
  int trial = 0;
  std::string text;  // the paradigm's words: "aborted: training failed: ..."
};

struct ParadigmPart {
  bci::Phase phase = bci::Phase::Setup;
  std::optional<bci::Phase> interrupted;
  int trial = 0, sequence = 0;
  // In the calibration run: the selection under way (1-based) of how many, and retakes so far.
  std::optional<std::pair<int, int>> calibration_selection;
  int calibration_retakes = 0;
  int reflashed_sequences = 0;  // begun again after an interruption (more flashes, no selection)
  bool errp_awaited = false;
  bci::FrameStimulus stimulus;            // what this frame shows
  std::vector<Flash> first_shown;         // flashes this frame shows for the first time
  std::optional<FeedbackShown> feedback;  // a selection this frame shows for the first time
  std::optional<SelectionStart> selection_started;
  std::vector<PhaseChange> phase_changes;  // entered this cycle
  std::vector<size_t> slots;               // stimulus code k: world.objects[slots[k - 1]]
  std::optional<int> selected_object;      // the marker id selected in this trial
  std::shared_ptr<const std::vector<TrialRecord>> trials;
  std::optional<bci::EvaluationReport> calibration;
  // Trained, before the first online trial: the calibration waits for the experimenter's Go
  // online or Recalibrate (gates.review, or its AUC below gates.min_auc).
  struct Review {
    double auc = 0.0, min_auc = 0.0;
    bool below = false;  // under gates.min_auc
    int round = 1;       // the calibration run's number (a recalibration is the second)
    // The AUC's 95 % interval and the flashes it was measured on, for its reference.
    double auc_low = 0.0, auc_high = 0.0;
    int targets = 0, others = 0;
  };
  std::optional<Review> review;
  // Paused by the session itself until something comes back ("every object in view for 1 s"):
  // it resumes by itself, so Resume is not the experimenter's to press. Empty otherwise.
  std::string waiting_for;
  std::string status;  // the last reason given: a fault, a pause, a failed training
};

// What the HMD's render stage drew this cycle.
struct DisplayPart {
  bool redrawn = false;           // false: the same frame as the last one
  std::optional<bool> patch_lit;  // the photodiode patch as read back from the frame drawn
  bool photodiode = false;        // the frame carries a photodiode patch
};

struct PreflightPart {
  bool running = false;
  std::vector<std::string> lines;
  // The check passed but for the EEG's quality (gates.signal_quality "ask"): the bad channels,
  // which the experimenter may accept with StartRequest{despite_quality}.
  std::vector<std::string> questioned;
  // The check asks about the display (too slow for display_hz): the question, which the
  // experimenter answers with StartRequest{despite_display} (run annotated), else "".
  std::string display_question;
};

struct CycleRecord {
  // The cycle's own time (the session's): as in Cycle.
  std::int64_t frame = 0;
  double time_s = 0.0, due_s = 0.0, host_s = 0.0;
  std::int64_t eeg_sample = 0;
  // This cycle's frame reached the screen at `host_s`, the EEG sample then being `sample` (set by
  // the window's owner once the buffer swap is done; headless, by the session).
  struct Presented {
    double host_s = 0.0;
    std::int64_t sample = 0;
  };
  std::optional<Presented> presented;
  // Each stage's compute time this cycle (ms), by name; the whole cycle's; the cycles so far whose
  // compute time exceeded the EEG block's (the session's count).
  std::map<std::string, double> stage_ms;
  double compute_ms = 0.0;
  int overruns = 0;
  // Who and which run (the start screen may change them until Start).
  core::RunLabels labels;

  Presentation presentation;  // the frame presented last
  EegPart eeg;
  QualityPart quality;
  RecordingPart recording;
  P300Part p300;
  ErrpPart errp;
  CameraPart cameras;
  RobotPart robot;
  TrackingPart tracking;
  PreflightPart preflight;
  ParadigmPart paradigm;
  DisplayPart display;
  // Notes for the recording (and the LSL Markers stream), in the order made; recorded next cycle.
  std::vector<bci::Annotation> annotations;
  // Requests to act on this cycle (posted last cycle, or by the experimenter between frames).
  std::vector<Request> requests;
  // Requests posted this cycle, for the next.
  std::vector<Request> posted;
  // The run should end after this cycle, and why ("" while it goes on). Once the session has
  // ended, its last record says so (`ended`) with the whole reason, how it ended ("finished",
  // "aborted", "estop", "fault") and summary.json's contents.
  std::string end_reason, end_kind;
  bool ended = false;
  std::shared_ptr<const nlohmann::json> summary;
};

struct Cycle {
  std::int64_t frame = 0;       // the display frame being made
  double time_s = 0.0;          // session seconds at the cycle's start
  double due_s = 0.0;           // when this frame is due on screen (session seconds)
  double host_s = 0.0;          // time_s on the host clock
  std::int64_t eeg_sample = 0;  // the EEG sample taken at time_s (the acquisition stage's)
  const Clock& clock;
  CycleRecord& record;
  const CycleRecord& previous;

  void post(Request request) { record.posted.push_back(std::move(request)); }
  void annotate(std::int64_t sample, std::string text) {
    record.annotations.push_back({sample, std::move(text), 0});
  }
  void end(std::string reason, std::string kind = "") {
    if (!record.end_reason.empty()) return;
    record.end_reason = std::move(reason);
    record.end_kind = std::move(kind);
  }
};

}  // namespace arbci::session
