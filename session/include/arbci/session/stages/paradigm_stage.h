// The paradigm's stage, where the cycle decides: what this frame shows (the paradigm's stimulus,
// scheduled in time, flashes withheld for objects whose pose is stale), each new flash labelled
// by what the subject attends, and what the paradigm asks for, posted on the record: a
// selection's stimuli (to the EEG stages and the simulated subject), training, the robot's
// grasp, put-down and stop. It takes the classifier's decisions (with dynamic stopping), the
// ErrP verdicts, the robot's outcomes and the trained models from the record, keeps the trial
// records, and pauses while the EEG source is in fault. The objects offered are those the
// cameras see.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "arbci/bci/paradigm.h"
#include "arbci/session/grasp_view.h"
#include "arbci/session/session_config.h"
#include "arbci/session/stage.h"
#include "arbci/session/trial_record.h"

namespace arbci::session {

struct ParadigmStageSettings {
  bci::ParadigmSettings paradigm;
  WorldSettings world;  // the objects (stimulus code k: the k-th offered) and the grid
  std::string classifier_method;
  std::vector<TrialIntent> intended;  // each trial's intention (the simulated subject's)
  std::uint64_t seed;                 // the paradigm's random flash order
  double errp_threshold = 0.5;        // ErrP: reject a selection above this posterior of error
  std::filesystem::path model_file;   // where the model trained goes
  bool experimenter = false;  // someone at the window: a wait pauses rather than ends the run
};

// What each stimulus code of the recording stands for: "1=object 20;2=object 40;...;101=row 1;
// ...;104=column 1;..." (object codes k for world.objects[slots[k - 1]], grid codes 100 + code).
std::string stimulusCodeMap(const WorldSettings& world, const std::vector<size_t>& slots);
// Every object offered, in the session file's order (before the cameras say what is in view).
std::vector<size_t> allSlots(const WorldSettings& world);

class ParadigmStage final : public Stage {
 public:
  ParadigmStage(const ParadigmStageSettings& settings, const StageServices& services);
  const char* name() const override { return "paradigm"; }
  void step(Cycle& cycle) override;
  // summary.json's "trials", "objects", "cells", "all_inclusive", "calibration" and "errp".
  void report(nlohmann::json& summary) const override;

 private:
  void act(const Request& request, Cycle& cycle);
  // Files how fresh the grasped object's pose stayed while the arm came down on it.
  void watchGrasp(Cycle& cycle);
  void takeRobotNotes(Cycle& cycle);
  void collectTraining(Cycle& cycle);
  void handleEvents(Cycle& cycle);
  void decideIfReady(const Cycle& cycle);
  // The ErrP verdict on the selection shown, once its feedback epoch is scored.
  void judgeFeedback(Cycle& cycle);
  // The verdict on the trial's last selection, for the summary.
  void markVerdict(bool veto);
  void watchEegSource(Cycle& cycle);
  // A selection with every flash withheld for paradigm.no_view_pause_s: a pause with the reason
  // (or, with nobody at the window, the end), never a silent wait.
  void watchWithheldFlashes(Cycle& cycle);
  // A calibration flash withheld: the selection stops there, paused until every object is in
  // view again, and is then retaken (training needs whole selections).
  void pauseCalibrationForView(int object_id, Cycle& cycle);
  // The paradigm paused until every offered object has been in view for a second; `why` names
  // the stop for a calibration retake, `status` is the panel's reason.
  void pauseForView(const std::string& why, const std::string& status, double time);
  void noteRetake(int target_code, Cycle& cycle);
  // "no object in view: the reference marker or objects (10, 40) lost for 10 s (...), CONTEXT"
  std::string viewLostReason(const std::string& context) const;
  TrialRecord& currentTrial();
  // The codes the subject means in this trial's current selection (objects or cell).
  std::set<int> intendedCodes(bool objects) const;
  void chooseSelectableObjects(Cycle& cycle);
  void nameObjects();  // the paradigm's texts name the offered objects by marker id
  // Objects whose pose is stale are not lit (nor their flashes recorded) on this frame.
  void withholdStaleFlashes(Cycle& cycle);
  // The attended codes of a new online selection: the intended object's, or cell's row and column.
  std::set<int> attendedCodes(bool objects, const Cycle& cycle);
  void recordSelection(const bci::ParadigmEvent& e, Cycle& cycle);
  const WorldObjectSettings& objectOfCode(int code) const;
  // The tracked object (other than the one in the gripper) standing on a grid cell, if any.
  std::optional<int> objectOnCell(std::pair<int, int> cell, const Cycle& cycle) const;
  std::optional<int> selectedObjectId() const;
  void publish(Cycle& cycle);

  ParadigmStageSettings settings_;
  StageServices s_;
  std::unique_ptr<bci::Paradigm> paradigm_;
  ParadigmPart& out(Cycle& cycle) { return cycle.record.paradigm; }
  bci::FrameStimulus stimulus_;
  std::vector<size_t> slots_;
  std::vector<TrialRecord> trials_;
  GraspView grasp_view_;  // the grasped object's tracking while the arm comes down on it
  std::optional<bci::EvaluationReport> calibration_report_;
  // The selection in progress: its number, its stimuli, and the codes the subject attends
  // (empty: not known) that label each flash.
  int selection_ = 0;
  bool selection_objects_ = true;
  std::set<int> truth_;
  int selection_flashes_ = 0;
  double last_trial_end_ = 0.0;  // where the next trial's time starts (session seconds)
  // Training: when it began, what is still awaited, and the frames presented meanwhile.
  double training_since_ = 0.0;
  bool awaiting_p300_ = false, awaiting_errp_ = false;
  std::optional<bci::EvaluationReport> errp_report_;
  std::string errp_failure_;
  int watch_frames_ = 0;
  double watch_longest_s_ = 0.0;
  std::optional<double> watch_last_at_;
  bool retrying_ = false;
  double shown_certainty_ = 0.0;  // the P300 certainty of the selection shown
  std::optional<bool> shown_error_;
  std::optional<double> errp_score_;  // the latest feedback's, until a verdict takes it
  struct ErrpCounts {
    int decisions = 0;  // verdicts on selections shown
    int wrong_shown = 0, wrong_caught = 0;
    int correct_shown = 0, correct_vetoed = 0;
    int runner_up = 0, repeats = 0, skipped_trials = 0;
    double correction_s = 0.0;  // from each rejection to the next accepted selection
  };
  ErrpCounts errp_counts_;
  double vetoed_since_ = -1.0;  // session time of the first rejection not yet made good
  std::set<int> stale_;         // offered objects whose pose is stale (marker ids)
  // An EEG source fault pauses the paradigm; it resumes once the source has delivered 2 s again.
  bool paused_for_eeg_ = false;
  double eeg_ok_since_ = -1.0;
  // Since when every flash of the selection has been withheld (-1: a flash was shown since);
  // a pause for that resumes once every offered object has been in view for a second.
  double withheld_since_ = -1.0;
  bool paused_for_view_ = false;
  double view_paused_at_ = -1.0;
  double in_view_since_ = -1.0;
  // Why the paradigm last stopped (a calibration selection interrupted there is retaken), and
  // the retakes: the selection cut, its target, why, and its retake's number.
  std::string stopped_because_;
  struct Retake {
    int selection = 0, object = 0;
    std::string reason;
    int retaken_as = 0;
  };
  std::vector<Retake> retakes_;
  std::vector<int> trained_on_;  // the calibration selections the classifier was trained on
  std::string status_;
};

}  // namespace arbci::session
