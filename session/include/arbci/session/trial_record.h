// One online trial as the session records it (intended and selected object and cell, flashes,
// the selections' times as presented, the placement), its line for the panel and the terminal,
// and the summary's per-trial list with the rates over all trials.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace arbci::session {

// One selection made in a trial (an ErrP rejection makes another): what was selected, and the
// ErrP classifier's verdict on it (nullopt: none was asked; executed as selected).
struct SelectionMade {
  bool object = true;  // an object's selection, else a cell's
  int object_id = -1;
  std::pair<int, int> cell{0, 0};
  bool correct = false;
  std::optional<bool> vetoed;
};

struct TrialRecord {
  int trial = 0;
  int intended_object = -1, selected_object = -1;
  std::pair<int, int> intended_cell{0, 0}, selected_cell{0, 0};
  double object_certainty = 0.0, cell_certainty = 0.0;
  int object_flashes = 0, cell_flashes = 0;
  double object_selection_s = 0.0, cell_selection_s = 0.0;  // from the presented onsets
  // Within each selection, the time the session stood interrupted (not in the times above).
  double object_interrupted_s = 0.0, cell_interrupted_s = 0.0;
  // Each pause, E-STOP and robot fault in the trial: what, when, and when it ended (resumed, or
  // another took over; -1: never).
  struct Interruption {
    std::string kind;  // "paused", "emergency stop", "robot fault"
    double at_s = 0.0, resumed_s = -1.0;
  };
  std::vector<Interruption> interruptions;
  double started_s = 0.0, ended_s = -1.0;  // session time: after the last trial, its put-down
  double placement_error_m = -1.0;
  std::string outcome = "incomplete";
  std::vector<SelectionMade> selections;  // in the order made
  // Where the robot was sent in this trial: the object it grasped, the cell it put it on
  // (nullopt: it did not go); returned: it put the object back where it was taken.
  std::optional<int> robot_object;
  std::optional<std::pair<int, int>> robot_cell;
  bool robot_returned = false;
  // While the arm came down on robot_object to grasp it (the gripper's fingers over its marker),
  // the oldest its tracked pose grew, seconds; -1 when it had none at some point, nullopt when
  // no grasp came down.
  std::optional<double> grasp_pose_age_max_s;
  // Learning from use (paradigm.calibration none, or adapt): the arm was held (the model not yet
  // trusted, or none yet); the object the last fit decodes for this trial's object selection, post
  // hoc, and (adapting) the one the calibrated model decodes on the same epochs.
  bool arm_held = false;
  std::optional<int> post_hoc_object, frozen_object;
  // The last object (cell) selection the ErrP classifier did not reject: what was executed.
  std::optional<int> acceptedObject() const;
  std::optional<std::pair<int, int>> acceptedCell() const;
  // Robot motions to another object or cell than the intended one (0, 1 or 2).
  int wrongRobotActions() const;
};

// "trial 2: object 40 (intended), cell 3,1 (intended 2,2), placed 2.2 mm off [placed]".
std::string selectionLine(const TrialRecord& trial);

// The summary's "trials" (each with the selections made and vetoed, the accepted ones or null,
// and where the robot went or null), "wrong_robot_actions", "objects" and "cells" (accuracy,
// seconds per selection and bits per minute, timed from the flash onsets as presented) and
// "all_inclusive" (over all of each completed trial's time: cues, pauses, feedback, the robot)
// and "first_right_placement_s" (when the first trial whose object and cell were both the
// intended ones ended, session seconds from Start; null: none).
nlohmann::json trialsSummary(const std::vector<TrialRecord>& trials, int object_choices,
                             int cell_choices);

}  // namespace arbci::session
