// The paradigm's stage, where the cycle decides: what this frame shows (the paradigm's stimulus,
// scheduled in time), and what the paradigm asks for, carried out: a selection's stimuli told to
// the EEG stage (and the simulated subject what it attends), training started and its model
// taken, the classifier's decisions (with dynamic stopping), the robot's grasp, put-down and stop,
// the trial records. The objects offered are those the cameras see.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <vector>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/paradigm.h"
#include "session/eeg_stage.h"
#include "session/robot_choreography.h"
#include "session/session_config.h"
#include "session/session_log.h"
#include "session/stage.h"
#include "session/stimulus_timing.h"
#include "session/trial_record.h"
#include "session/vision_stage.h"

namespace arbci::app {

// What the paradigm's stage needs of the session file, and nothing else.
struct ParadigmStageSettings {
  bci::ParadigmSettings paradigm;
  WorldSettings world;  // the objects (stimulus code k: the k-th offered) and the grid
  std::string classifier_method;
  std::vector<TrialIntent> intended;  // each trial's intention (the simulated subject's)
  std::uint64_t seed;                 // the paradigm's random flash order
  double errp_threshold = 0.5;        // ErrP: reject a selection above this posterior of error
  static ParadigmStageSettings of(const SessionConfig& config);
};

// What each stimulus code of the recording stands for: "1=object 20;2=object 40;...;101=row 1;
// ...;104=column 1;..." (object codes k for world.objects[slots[k - 1]], grid codes 100 + code).
std::string stimulusCodeMap(const WorldSettings& world, const std::vector<size_t>& slots);
// Every object offered, in the session file's order (before the cameras say what is in view).
std::vector<size_t> allSlots(const WorldSettings& world);

class ParadigmStage final : public Stage {
 public:
  struct Services {
    EegStage& eeg;
    VisionStage& vision;
    RobotChoreography& robot;
    StimulusTiming& timing;
    SessionLog& log;
    std::ostream* progress = nullptr;
  };
  // `now`: the session's current cycle (the experimenter's calls between frames and the robot's
  // hooks use its time). `wait_for_training`: a simulated clock waits for the worker (the same
  // frame every run); a live cycle looks each frame. The model trained goes to `model_file`.
  ParadigmStage(const ParadigmStageSettings& settings, const CycleContext& now,
                bool wait_for_training, std::filesystem::path model_file, Services services);

  const char* name() const override { return "paradigm"; }
  void step(CycleContext& cycle) override;

  // The experimenter.
  void start();
  void emergencyStop();
  // Recovery (Session checks first that it is safe): the interrupted robot step again, or the
  // trial ended as it stands.
  void retryStep();
  void skipTrial();
  // The marker id of the object selected in this trial, once selected.
  std::optional<int> selectedObjectId() const;

  // What this frame shows, and the codes it shows for the first time (flash onsets, stamped when
  // the frame is presented).
  const bci::FrameStimulus& stimulus() const { return stimulus_; }
  const std::vector<int>& firstShown() const { return first_shown_; }
  // A selection's feedback this frame shows for the first time (stamped when presented).
  struct FeedbackShown {
    std::set<int> codes;
    bool objects = true;
    std::optional<bool> error;  // known: the calibration block's, or against the intention
  };
  const std::optional<FeedbackShown>& feedbackShown() const { return feedback_shown_; }
  // What the ErrP classifier did in this session (summary.json's "errp").
  struct ErrpCounts {
    int decisions = 0;  // verdicts on selections shown
    int wrong_shown = 0, wrong_caught = 0;
    int correct_shown = 0, correct_vetoed = 0;
    int runner_up = 0, repeats = 0, skipped_trials = 0;
    double correction_s = 0.0;  // from each rejection to the next accepted selection
  };
  const ErrpCounts& errpCounts() const { return errp_counts_; }
  struct PhaseChange {
    bci::Phase phase;
    int trial;
  };
  // The phases entered since the last step began.
  const std::vector<PhaseChange>& phaseChanges() const { return phase_changes_; }
  // The objects offered: stimulus code k stands for world.objects[slots()[k - 1]].
  const std::vector<size_t>& slots() const { return slots_; }

  // From the robot's part of a trial.
  TrialRecord& currentTrial();
  TrialRecord& trial(int number);  // from 1
  void robotFinished(bool success, const std::string& why);
  // Home after a put-down, the table seen again: the next trial offers what the cameras see.
  void putDownEnded();

  bci::Paradigm& paradigm() { return *paradigm_; }
  const bci::Paradigm& paradigm() const { return *paradigm_; }
  const std::vector<TrialRecord>& trials() const { return trials_; }
  const std::optional<bci::EvaluationReport>& calibrationReport() const {
    return calibration_report_;
  }

 private:
  void handleEvents();
  void collectTraining();
  void decideIfReady();
  // The ErrP verdict on the selection shown, once its feedback epoch is scored.
  void judgeFeedback();
  // The codes the subject means in this trial's current selection (objects or cell).
  std::set<int> intendedCodes(bool objects) const;
  void chooseSelectableObjects();
  void nameObjects();  // the paradigm's texts name the offered objects by marker id
  // Objects whose pose is stale are not lit (nor their flashes recorded) on this frame.
  void withholdStaleFlashes();
  // The attended codes of a new online selection: the intended object's, or cell's row and column.
  std::set<int> attendedCodes(bool objects);
  void recordSelection(const bci::ParadigmEvent& e);
  const WorldObjectSettings& objectOfCode(int code) const;
  // The tracked object (other than the one in the gripper) standing on a grid cell, if any.
  std::optional<int> objectOnCell(std::pair<int, int> cell) const;

  ParadigmStageSettings settings_;
  const CycleContext& now_;
  bool wait_for_training_;
  std::filesystem::path model_file_;
  Services s_;
  std::unique_ptr<bci::Paradigm> paradigm_;
  bci::FrameStimulus stimulus_;
  std::vector<int> first_shown_;
  std::vector<PhaseChange> phase_changes_;
  std::vector<size_t> slots_;
  std::vector<TrialRecord> trials_;
  std::optional<bci::EvaluationReport> calibration_report_;
  int selection_flashes_ = 0;
  double last_trial_end_ = 0.0;  // where the next trial's time starts (session seconds)
  double training_since_ = 0.0;
  bool retrying_ = false;
  std::optional<FeedbackShown> feedback_shown_;
  double shown_certainty_ = 0.0;  // the P300 certainty of the selection shown
  std::optional<bool> shown_error_;
  ErrpCounts errp_counts_;
  double vetoed_since_ = -1.0;  // session time of the first rejection not yet made good
  std::set<int> stale_;  // offered objects whose pose is stale (marker ids)  // the robot events
                         // come from the experimenter's Retry step
};

}  // namespace arbci::app
