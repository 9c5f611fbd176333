// The paradigm's stage, where the cycle decides. The trial's states and their transitions are
// bci::Paradigm's (docs/architecture.md has the table); this stage drives it from the record and
// carries out what it asks for:
//   - in: the experimenter's requests (begin, pause, resume, abort, emergency stop, retry, skip,
//     end), the classifier's decisions (with dynamic stopping), the ErrP's scores, the trained
//     models, the robot's notes (every answer of the robot reaches the paradigm this way), the
//     EEG source's fault, what tracking sees;
//   - out: what this frame shows (flashes withheld for objects whose pose is stale), each new
//     flash labelled by what the subject attends, a selection's stimuli (to the EEG stages and the
//     simulated subject), training, the robot's grasp, put-down and stop, the recording's notes,
//     and the trials' records for the summary.
// The objects offered are those the cameras see. Its helpers (session/paradigm/) keep the trials,
// the ErrP's verdicts, the pauses it makes by itself, and the calibration run's end.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "arbci/bci/paradigm.h"
#include "arbci/session/grasp_view.h"
#include "arbci/session/paradigm/calibration_run.h"
#include "arbci/session/paradigm/errp_judge.h"
#include "arbci/session/paradigm/pause_watch.h"
#include "arbci/session/paradigm/trial_book.h"
#include "arbci/session/session_config.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct ParadigmStageSettings {
  bci::ParadigmSettings paradigm;
  WorldSettings world;  // the objects (stimulus code k: the k-th offered) and the grid
  std::string classifier_method;
  std::vector<TrialIntent> intended;  // each trial's intention (the simulated subject's)
  std::uint64_t seed;                 // the paradigm's random flash order
  // ErrP: reject a selection above this posterior of error (errp.threshold).
  double errp_threshold = ErrpSettings().threshold;
  std::filesystem::path model_file;  // where the model trained goes
  bool experimenter = false;    // someone at the window: a wait pauses rather than ends the run
  double max_pose_age_s = 0.0;  // tracker.max_pose_age_s: older is stale (the robot refuses it)
  bool review = false;          // gates.review: the experimenter accepts the calibration
  double min_auc = 0.0;         // gates.min_auc (0: none)
  int max_retakes = std::numeric_limits<int>::max();  // gates.max_retakes (none unless given)
  bool learns = false;  // no calibration run: the P300 stage learns from the trials
};

// A learning trial's outcome (paradigm.calibration none): its object selection shown (or none
// made, before the first model), the arm not sent because the model is not yet trusted, or because
// the fit with the selection in (trusted) decodes it as another object than was shown, or because
// the online decision was less certain than dynamic stopping asks, or because the fit failed.
inline constexpr const char* kArmHeld =
    "learning: the model is not yet trusted, so the arm was not sent";
inline constexpr const char* kArmHeldUnconfirmed =
    "learning: the fit with this selection in decodes it as another object, so the arm was not "
    "sent";
inline constexpr const char* kArmHeldUncertain =
    "learning: the selection was less certain than paradigm.certainty, so the arm was not sent";
inline constexpr const char* kArmHeldFitFailed =
    "learning: the fit with this selection in failed (see the log's learning_fit_failed), so the "
    "arm was not sent";

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
  void stop(Cycle& cycle, const std::string& reason) override;
  void report(nlohmann::json& summary) const override;

 private:
  // In.
  void act(const Request& request, Cycle& cycle);
  void takeRobotNotes(Cycle& cycle);
  void recoverUnattended(const std::string& why, Cycle& cycle);
  void watchGrasp(Cycle& cycle);
  void collectTraining(Cycle& cycle);
  // Trained: online at once, or the review first (or, below the minimum AUC with nobody to ask,
  // the end of the run).
  void reviewCalibration(Cycle& cycle);
  void goOnline(Cycle& cycle);
  void answerReview(bool go_online, Cycle& cycle);
  void decideIfReady(const Cycle& cycle);
  void judgeFeedback(Cycle& cycle);
  // The paradigm's events, each to its handler.
  void handleEvents(Cycle& cycle);
  void onPhaseChanged(const bci::ParadigmEvent& e, Cycle& cycle);
  void noteInterruption(const bci::ParadigmEvent& e, double time_s);
  void onSelectionStarted(const bci::ParadigmEvent& e, Cycle& cycle);
  void onFlash(const bci::ParadigmEvent& e, Cycle& cycle);
  void onSelectionMade(const bci::ParadigmEvent& e, Cycle& cycle);
  void onFeedback(const bci::ParadigmEvent& e, Cycle& cycle);
  void onErrpCorrection(const bci::ParadigmEvent& e, Cycle& cycle);
  void onTrainModel(Cycle& cycle);
  void onRobotGrasp(const bci::ParadigmEvent& e, Cycle& cycle);
  void onRobotDrop(const bci::ParadigmEvent& e, Cycle& cycle);
  void onTrialDone(const bci::ParadigmEvent& e, Cycle& cycle);
  // The objects offered: those the cameras see (at least two), named in the paradigm's texts.
  void chooseSelectableObjects(Cycle& cycle);
  void nameObjects();
  // The codes the subject means in this trial's current selection (objects or cell); a new online
  // selection's attended codes (said when the intended object is not offered).
  std::set<int> intendedCodes(bool objects) const;
  std::set<int> attendedCodes(bool objects, const Cycle& cycle);
  const WorldObjectSettings& objectOfCode(int code) const;
  // The tracked object (other than the one in the gripper) standing on a grid cell, if any.
  std::optional<int> objectOnCell(std::pair<int, int> cell, const Cycle& cycle) const;
  void publish(Cycle& cycle);
  // Learning from use: each object selection judged by the fit with it in; each one's post-hoc
  // decoding (and, adapting, the calibrated model's) onto its trial.
  void followLearning(const Cycle& cycle);
  // Learning from use and the model not (yet) trusted: a selection is data to learn from, with all
  // its sequences (no dynamic stopping).
  bool untrusted(const Cycle& cycle) const;
  // Every object selection waits for the fit with it in; a trusted fit that decodes it as shown
  // sends its trial on to the arm (bci::Paradigm::judgeHeldSelection).
  void judgeHeldSelection(const Cycle& cycle);

  ParadigmStageSettings settings_;
  StageServices s_;
  bci::Paradigm paradigm_;
  bci::FrameStimulus stimulus_;
  std::vector<size_t> slots_;  // code k: world.objects[slots_[k - 1]]
  TrialBook trials_;
  ErrpJudge errp_;
  CalibrationRun calibration_;
  EegFaultWatch eeg_watch_;
  ViewWatch view_watch_;
  StopReasons reasons_;
  GraspView grasp_view_;  // the grasped object's tracking while the arm comes down on it
  // The selection in progress: its number, its stimuli, the codes the subject attends (empty:
  // not known) that label each flash, and its flashes shown.
  int selection_ = 0;
  bool selection_objects_ = true;
  std::set<int> truth_;
  int selection_flashes_ = 0;
  // Dynamic stopping ended this selection on this code: certain enough then, as the certainty
  // condition of learning's arm asks, though the flashes still being scored may lower it a little.
  std::optional<std::pair<int, int>> stopped_certain_;  // (selection, code)
  bool retrying_ = false;  // the experimenter's Retry step is being carried out
  std::optional<ParadigmPart::Review> review_;  // the calibration awaiting the experimenter
  int calibration_round_ = 1;
  // Learning: each online object selection's trial and the object ids its codes stood for.
  struct LearntSelection {
    int trial = 0;
    std::vector<int> ids;
  };
  std::map<int, LearntSelection> learnt_;
  std::shared_ptr<const LearningState> learning_seen_;
  std::optional<int> first_trusted_trial_;
};

}  // namespace arbci::session
