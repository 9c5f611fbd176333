// The experiment as the experimenter drives it: set-up, a calibration run (copy task: the target
// is cued and data are recorded for training), then online trials. A trial selects an object
// (every visible object flashes alone, in random order within each sequence), has the robot
// grasp it, selects a place (rows and columns of the grid flash as in the P300 speller) and has
// the robot put the object there. Pause, abort and emergency stop work in every state.
//
// It is driven by displayed frames but scheduled in time: frame(i, due_s) says what frame i, due
// on screen at `due_s`, shows. Flash onsets follow the SOA (60 ms flash, 120 ms interval, each
// rounded to whole frames of the nominal display rate), decided ahead; a display slower than its
// nominal rate shows each flash on the first frame due at or after its onset (never two new
// flashes on one frame), for the flash's duration from there. The cycle stamps each flash with the
// presentation time of the frame that first shows it. The cycle feeds it the
// classifier's decisions, the end of training and the robot's outcomes, and takes its events
// (flash onsets, phase changes, selections, robot commands).
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "arbci/bci/decision.h"
#include "arbci/bci/paradigm_layout.h"
#include "arbci/bci/stimulus_sequence.h"

namespace arbci::bci {

// Each field's default, range and meaning: bci::paradigmSchema() (bci/settings.h).
struct ParadigmSettings {
  ParadigmSettings();  // the schema's defaults
  double display_hz;
  double flash_ms;
  double isi_ms;
  int sequences;              // per online selection (the maximum with dynamic stopping)
  int calibration_sequences;  // per calibration selection (always all)
  int min_sequences;          // dynamic stopping never stops earlier
  double certainty;           // dynamic stopping's (and learning's arm's) threshold; 0: none
  double act_certainty;       // a calibrated run's arm acts on nothing less probable; 0: none
  double cue_s;               // calibration: the target is shown before its flashes
  double result_s;            // a selection is shown this long
  double pause_s;             // between selections
  // A selection whose every flash was withheld (its objects out of view) this long pauses the
  // session with the reason (one without an experimenter ends); the session stage enforces it.
  double no_view_pause_s;
  int calibration_selections;
  int trials;
  // "cued": a calibration run trains the classifier before the trials (unless a model is given);
  // "none": the trials start at once and the classifier learns from them without labels
  // (docs/classification.md, "Learning from use"). While it learns, the arm is not sent: each
  // trial is an object selection only, until the model is trusted: `learning_min_selections`
  // selections learnt from, a leave-one-out consistency of at least `learning_min_consistency`
  // (bci/unsupervised.h), and its decoding of the earlier selections unchanged since the last fit
  // (but for a tenth of them).
  // Until then an object selection flashes `learning_sequences` (0: as many as
  // `learning_max_sequences` allows), all of them: nothing is acted on, so the trial's time is
  // spent on evidence for the fit (a weak P300 is found in longer selections where it is not in
  // shorter ones). Once the model is trusted, an object selection goes on flashing until dynamic
  // stopping ends it (the arm acts only on a selection at least `certainty` probable), up to
  // `learning_max_sequences` (0: twice `sequences`): a selection the arm would be held for costs
  // the trial, more sequences cost seconds.
  std::string calibration;
  int learning_min_selections;
  double learning_min_consistency;
  int learning_sequences;
  int learning_max_sequences;
  // A calibrated session goes on learning from its object selections, the calibration run's
  // labels kept: the model is retrained after each with the labels EM finds for the rest.
  bool adapt;
  // The timing check's mode, not a setting: cued calibration selections without end (never
  // training, never trials).
  bool flashes_only = false;
  // Error-related potentials (docs/errp.md). A selection is shown for `result_s` as feedback,
  // and the robot waits for the ErrP verdict on it; a rejected selection is replaced by the
  // runner-up when, among the rest, it holds at least `errp_runner_up` of the probability (shown
  // after `pause_s` with nothing selected, so that its ErrP epoch does not start in the tail of
  // the rejected one's response, as the calibration block's feedbacks never do), otherwise the
  // selection is made again with `errp_repeat_sequences` sequences (0: twice `sequences`); after
  // `errp_max_corrections` rejections the trial is skipped (an object already grasped is put back
  // where it was taken). The calibration run ends with `errp_calibration_feedbacks` cued feedbacks,
  // `errp_wrong_rate` of them deliberately wrong (in random order).
  bool errp;
  int errp_calibration_feedbacks;
  double errp_wrong_rate;
  double errp_runner_up;
  int errp_repeat_sequences;
  int errp_max_corrections;

  int flashFrames() const;  // frames a flash lasts (60 ms at 60 Hz: 4)
  int onsetFrames() const;  // frames from one flash onset to the next (180 ms: 11)
  double flashSeconds() const { return flashFrames() / display_hz; }
  double soaSeconds() const { return onsetFrames() / display_hz; }
  // Learning from use's object selections, their zeros resolved: a trusted one's most sequences,
  // an untrusted one's.
  int trustedMaxSequences() const {
    return learning_max_sequences > 0 ? learning_max_sequences : 2 * sequences;
  }
  int untrustedSequences() const {
    return learning_sequences > 0 ? learning_sequences : trustedMaxSequences();
  }
};

enum class Phase {
  Setup,
  CalibrationCue,
  CalibrationFlashing,
  CalibrationFeedback,  // the ErrP block: a cued object shown as if selected (maybe wrongly)
  Training,
  ObjectFlashing,
  ObjectSelected,
  Grasping,
  CellFlashing,
  CellSelected,
  Dropping,
  Finished,
  Aborted,
  Paused,
  EmergencyStop,
  RobotFault,
};
const char* toString(Phase phase);
// A recording's annotation of a phase change: this prefix, then the PhaseChanged event's text
// (toString(phase), then ": " and details when it has some).
inline constexpr const char* kPhaseAnnotation = "Phase ";

// What one displayed frame shows.
struct FrameStimulus {
  Phase phase = Phase::Setup;
  bool grid_visible = false;
  std::set<int> lit;               // codes lit on this frame (objects, or grid rows/columns)
  std::optional<int> cued_object;  // 1-based object slot
  std::optional<int> selected_object;
  std::optional<std::pair<int, int>> cued_cell, selected_cell;  // (row, column)
};

struct ParadigmEvent {
  enum class Kind {
    PhaseChanged,  // text: the phase
    // Layout, target codes (calibration) in `codes`; `retake`: a calibration selection that
    // was interrupted, cued again (its flashes so far are no whole selection to train on).
    SelectionStarted,
    Flash,          // code, onset frame
    SelectionMade,  // codes chosen, certainty (text "runner-up" for an ErrP correction)
    Feedback,       // a selection first shown (codes); calibration: `error` says if wrong
    // After a rejected selection, text: "runner-up", "repeat", "skip" (no object held yet: the
    // trial ends) or "return" (no cell accepted: the object goes back where it was taken).
    ErrpCorrection,
    TrainModel,  // the calibration run is complete: train now and call modelTrained()
    RobotGrasp,  // object slot in `object`
    RobotDrop,   // cell in `cell`; `give_back`: put the object back where it was taken (text: why)
    RobotStop,
    TrialDone,
  };
  explicit ParadigmEvent(Kind k) : kind(k) {}
  Kind kind;
  std::int64_t frame = 0;
  Phase phase = Phase::Setup;
  int code = 0;
  int object = 0;
  std::pair<int, int> cell{0, 0};
  std::set<int> codes;
  bool objects_layout = true;  // the selection's stimuli are objects (else grid rows/columns)
  bool give_back = false;
  bool arm_held = false;  // TrialDone: ended with the arm held (learning from use; text says why)
  double certainty = 0.0;
  int trial = 0;
  std::string text;
  std::optional<bool> error;  // Feedback in the calibration run: deliberately wrong
  bool retake = false;        // SelectionStarted: the interrupted calibration selection again
};

class Paradigm {
 public:
  // `objects`: how many objects can be selected; `grid`: the grid's rows and columns.
  Paradigm(const ParadigmSettings& settings, int objects, int rows, int columns,
           std::uint64_t seed);

  // Experimenter controls (any state).
  void start(bool calibrate);  // from Setup: with a calibration run, or straight to the trials
  void pause();
  // Also acknowledges a robot fault or an emergency stop: an interrupted selection starts its
  // sequence again; a trial whose robot step was interrupted is over (the next one starts). The
  // session checks first that the arm is home and holds nothing. An interrupted calibration
  // selection goes on the same way, unless `retake`: then it is retaken, its target cued again
  // and all its sequences flashed anew (for a selection some of whose flashes were withheld).
  void resume(bool retake = false);
  // After a hold (a stall of the machine, not of the subject): the paused flashing goes on with
  // its current sequence again, a calibration selection included (not retaken).
  void resumeHeld();
  void abort();
  void emergencyStop();
  // The experimenter's recovery after an emergency stop or a robot fault. Retry: the interrupted
  // robot step (grasp or put-down) is asked for again, or an interrupted selection goes on.
  // Skip: the trial ends as it stands and the next one starts (or the run finishes).
  void retryStep();
  // `why`: the trial's outcome ("": skipped by the experimenter).
  void skipTrial(const std::string& why = "");
  // In an emergency stop or a robot fault: the phase it interrupted.
  std::optional<Phase> interrupted() const;

  // What frame `index`, due on screen at `due_s` (seconds of the session's clock), shows; call
  // once per displayed frame in order. Without `due_s`: the nominal rate's time of the frame.
  FrameStimulus frame(std::int64_t index, double due_s);
  FrameStimulus frame(std::int64_t index) { return frame(index, index / settings_.display_hz); }
  // Frame `index` reached the screen at `at_s` (the same clock as `due_s`): a late frame's flash
  // onset or dark frame counts from when it was shown, so the SOA and the dark gap the screen
  // shows are never shorter than the paradigm's, however late frames come.
  void presented(std::int64_t index, double at_s);

  // From the cycle: the classifier may end flashing early (dynamic stopping).
  void requestStopFlashing();
  // All epochs of the selection are scored: its decision.
  void decide(const Decision& decision);
  // The ErrP classifier's verdict on the selection shown (the robot waits for it when `errp`):
  // `error` rejects it. Ignored unless awaitingErrpVerdict().
  void errpVerdict(bool error);
  bool awaitingErrpVerdict() const;
  void modelTrained(bool ok, const std::string& text);
  // Learning from use (calibration "none"): while held, an object selection is shown and its trial
  // ends there, the arm not sent (`why` is the trial's outcome); a selection decided without a
  // model (no choice) ends its trial at once. Read when a selection is made.
  void holdArm(bool held, const std::string& why);
  // In every run the arm acts only on a selection the model is sure enough of (`act_certainty`;
  // learning from use: `certainty`, as dynamic stopping asks): an object shown below it is not
  // grasped (its trial ends), a cell below it is not put down on (the object goes back where it
  // was taken). Learning from use, trusted, a cell also gets the objects' room to reach it.
  void holdUncertainCells(bool hold) { hold_uncertain_cells_ = hold; }
  // How many sequences an online object selection flashes. Usual: `sequences`. Learning from use,
  // the model not trusted: `learning_sequences`, all of them. Trusted: up to
  // `learning_max_sequences` (dynamic stopping ends them once certain).
  enum class ObjectSequences { Usual, Learning, Trusted };
  void setObjectSequences(ObjectSequences mode);
  // A held object selection is fitted in with the rest once shown: while that fit is `pending`
  // the selection stays shown; when the fit came back trusted and decodes the selection as it was
  // shown (`act`), its trial goes on to the arm after all, instead of ending held (the selection
  // that earns the trust is not wasted); otherwise the trial ends with `why`. Read when the
  // selection's showing ends.
  void judgeHeldSelection(bool pending, bool act, const std::string& why);
  // From Training (the experimenter's Recalibrate at the review): the calibration run again, from
  // its first selection (and its ErrP block, where there is one).
  void recalibrate();
  void robotFinished(bool success, const std::string& text);
  // The number of objects that can be selected from the next trial on (those tracked).
  void setObjectCount(int objects);
  // What the objects are called in the phase texts (their marker ids, slot k at k - 1), so the
  // log, the panels and the recording name an object the same way; without: the slot number.
  void setObjectNames(std::vector<int> ids);
  std::string objectName(int slot) const;

  std::vector<ParadigmEvent> takeEvents();
  Phase phase() const { return phase_; }
  int trial() const { return trial_; }
  // ErrP rejections of the current selection so far.
  int corrections() const { return corrections_; }
  int sequence() const { return sequence_; }  // the current sequence of a flashing phase (1-based)
  int calibrationRetakes() const { return calibration_retakes_; }
  // Sequences begun again after an interruption: their flashes shown before it are kept, so the
  // selection has that many flashes more (counted apart, never as a selection).
  int reflashedSequences() const { return reflashed_sequences_; }
  // Calibration selections done so far (the one under way is this plus one).
  int calibrationDone() const { return calibration_done_; }
  bool calibrating() const { return calibrating_; }
  bool awaitingDecision() const { return awaiting_decision_; }
  const ParadigmLayout& objectLayout() const { return object_layout_; }
  const ParadigmLayout& gridLayout() const { return grid_layout_; }
  // The calibration target (1-based object) while cueing or flashing in the calibration run.
  std::optional<int> calibrationTarget() const { return calibration_target_; }
  const ParadigmSettings& settings() const { return settings_; }

 private:
  int objectSequences() const;  // the most sequences of an online object selection
  void enter(Phase phase, const std::string& text = "");
  void startFlashing(double at_s, bool objects);
  void cueCalibrationTarget(double at_s);  // the next calibration selection's (or feedback's) cue
  void showSelection(const std::set<int>& codes, int choice, double certainty, bool objects,
                     const std::string& text);
  void scheduleSequence(double first_onset_s);
  void restartSequence();  // an interrupted selection shows its sequence again from the start
  // Back to `phase` after an interruption: the sequence begun again, or (`retake`) the
  // calibration selection retaken.
  void returnToFlashing(Phase phase, bool retake);
  void retakeCalibrationSelection();
  void nextTrial(double at_s, const std::string& why, bool arm_held = false);
  void askRobot(Phase phase);  // Grasping or Dropping, with its command
  // frame()'s parts: a sequence over starts the next or ends the flashing; the flash due shown
  // (true) and those still lit; a timed phase (cue, feedback, selection shown) over moves on; what
  // the frame shows.
  void endSequenceIfOver(double due_s);
  void showFlashes(double due_s, FrameStimulus& out);
  bool showNextFlash(size_t i, double due_s);
  void advanceTimedPhase(double due_s);
  void showCalibrationFeedback(double due_s);
  void endCalibration();  // the last calibration selection or feedback: training
  void describe(FrameStimulus& out);
  double nextFrame() const { return now_ + 1.0 / settings_.display_hz; }
  void event(ParadigmEvent e);

  ParadigmSettings settings_;
  ParadigmLayout object_layout_, grid_layout_;
  std::mt19937_64 random_;
  std::optional<StimulusSequencer> sequencer_;
  Phase phase_ = Phase::Setup;
  Phase paused_from_ = Phase::Setup;
  std::int64_t frame_ = 0;       // the last frame shown
  double now_ = 0.0;             // its due time
  bool lit_last_frame_ = false;  // the last frame showed a flash
  // The last flash's onset, and the first frame after it that showed nothing (session seconds).
  double last_onset_s_ = -1e9, last_dark_s_ = -1e9;
  std::int64_t onset_frame_ = -1, dark_frame_ = -1;  // the frames they were due on
  double phase_until_ = 0.0;  // timed phases end then (while paused: the time still to go)
  // Flashing: the current sequence's flashes, and when each was first shown.
  struct ScheduledFlash {
    double onset_s;
    int code;
    double shown_s = -1.0;
  };
  std::vector<ScheduledFlash> schedule_;
  size_t next_flash_ = 0;
  int sequence_ = 0;
  bool stop_requested_ = false;
  bool awaiting_decision_ = false;
  bool flashing_objects_ = true;
  bool calibrating_ = false;
  int calibration_done_ = 0;
  int calibration_retakes_ = 0;
  int reflashed_sequences_ = 0;
  std::optional<int> calibration_target_;
  int trial_ = 0;
  std::optional<int> selected_object_;
  std::optional<std::pair<int, int>> selected_cell_;
  std::vector<ParadigmEvent> events_;
  std::vector<int> object_ids_;
  // ErrP.
  bool feedback_pending_ = false;    // the next frame is the first to show the selection
  bool verdict_pending_ = false;     // the selection shown waits for the ErrP verdict
  std::set<int> shown_codes_;        // the selection shown as feedback
  std::optional<bool> shown_error_;  // calibration feedback: deliberately wrong
  Decision last_decision_;
  bool runner_up_taken_ = false;
  bool runner_up_waiting_ = false;  // the rejected selection is cleared; the runner-up comes next
  bool giving_back_ = false;        // the put-down returns the object (no cell was accepted)
  std::string give_back_why_;       // and why
  bool hold_uncertain_cells_ = false;
  double shown_certainty_ = 0.0;   // of the selection shown
  bool shown_correction_ = false;  // the selection shown is an ErrP's runner-up
  bool unsure() const;             // the selection shown is below what the arm acts on
  double actThreshold() const;     // act_certainty; learning from use: certainty
  const char* actThresholdName() const;
  int corrections_ = 0;
  bool hold_arm_ = false, held_now_ = false;  // asked; latched for the selection shown
  ObjectSequences object_sequences_ = ObjectSequences::Usual;
  std::string hold_why_, held_why_;
  bool held_fit_pending_ = false, held_act_ = false;  // judgeHeldSelection's
  int sequences_override_ = 0;   // a repeated selection's fixed number of sequences
  bool errp_block_ = false;      // the calibration run's ErrP feedback block
  std::vector<bool> errp_plan_;  // the block's feedbacks: true = deliberately wrong
  size_t errp_done_ = 0;
};

}  // namespace arbci::bci
