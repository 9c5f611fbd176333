// One online trial as the session records it (intended and selected object and cell, flashes,
// the selections' times as presented, the placement), its line for the panel and the terminal,
// and the summary's per-trial list with the rates over all trials.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace arbci::session {

struct TrialRecord {
  int trial = 0;
  int intended_object = -1, selected_object = -1;
  std::pair<int, int> intended_cell{0, 0}, selected_cell{0, 0};
  double object_certainty = 0.0, cell_certainty = 0.0;
  int object_flashes = 0, cell_flashes = 0;
  double object_selection_s = 0.0, cell_selection_s = 0.0;  // from the presented onsets
  double started_s = 0.0, ended_s = -1.0;  // session time: after the last trial, its put-down
  double placement_error_m = -1.0;
  std::string outcome = "incomplete";
};

// "trial 2: object 40 (intended), cell 3,1 (intended 2,2), placed 2.2 mm off [placed]".
std::string selectionLine(const TrialRecord& trial);

// The summary's "trials", "objects" and "cells" (accuracy, seconds per selection and bits per
// minute, timed from the flash onsets as presented) and "all_inclusive" (over all of each
// completed trial's time: cues, pauses, feedback, the robot).
nlohmann::json trialsSummary(const std::vector<TrialRecord>& trials, int object_choices,
                             int cell_choices);

}  // namespace arbci::session
