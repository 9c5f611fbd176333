#include "arbci/session/trial_record.h"

#include <cstdio>

#include "arbci/bci/evaluation.h"

namespace arbci::session {

std::string selectionLine(const TrialRecord& t) {
  std::string line = "trial " + std::to_string(t.trial) + ": object ";
  line += t.selected_object >= 0
              ? std::to_string(t.selected_object) +
                    (t.selected_object == t.intended_object
                         ? " (intended)"
                         : " (intended " + std::to_string(t.intended_object) + ")")
              : "-";
  line += ", cell ";
  line += t.selected_cell.first > 0
              ? std::to_string(t.selected_cell.first) + "," +
                    std::to_string(t.selected_cell.second) +
                    (t.selected_cell == t.intended_cell
                         ? " (intended)"
                         : " (intended " + std::to_string(t.intended_cell.first) + "," +
                               std::to_string(t.intended_cell.second) + ")")
              : "-";
  if (t.placement_error_m >= 0.0) {
    char placed[48];
    std::snprintf(placed, sizeof placed, ", placed %.1f mm off", t.placement_error_m * 1000.0);
    line += placed;
  }
  return line + " [" + t.outcome + "]";
}

nlohmann::json trialsSummary(const std::vector<TrialRecord>& records, int object_choices,
                             int cell_choices) {
  nlohmann::json trials = nlohmann::json::array();
  int objects_right = 0, cells_right = 0, objects_made = 0, cells_made = 0, completed = 0;
  double object_seconds = 0, cell_seconds = 0, trial_seconds = 0;
  auto orNull = [](double v) { return v >= 0.0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
  for (const TrialRecord& t : records) {
    trials.push_back({{"trial", t.trial},
                      {"intended_object", t.intended_object},
                      {"selected_object", t.selected_object},
                      {"intended_cell", {t.intended_cell.first, t.intended_cell.second}},
                      {"selected_cell", {t.selected_cell.first, t.selected_cell.second}},
                      {"object_flashes", t.object_flashes},
                      {"cell_flashes", t.cell_flashes},
                      {"object_selection_s", t.object_selection_s},
                      {"cell_selection_s", t.cell_selection_s},
                      {"outcome", t.outcome},
                      {"duration_s", t.ended_s >= 0.0 ? orNull(t.ended_s - t.started_s)
                                                      : nlohmann::json(nullptr)},
                      {"placement_error_m", orNull(t.placement_error_m)}});
    if (t.selected_object >= 0) {
      ++objects_made;
      objects_right += t.selected_object == t.intended_object;
      object_seconds += t.object_selection_s;
    }
    if (t.selected_cell.first > 0) {
      ++cells_made;
      cells_right += t.selected_cell == t.intended_cell;
      cell_seconds += t.cell_selection_s;
    }
    if (t.ended_s >= 0.0) {
      ++completed;
      trial_seconds += t.ended_s - t.started_s;
    }
  }
  auto rate = [](int choices, int right, int made, double total_seconds) {
    if (made == 0) return nlohmann::json(nullptr);
    const double seconds = total_seconds / made;
    return nlohmann::json{
        {"accuracy", static_cast<double>(right) / made},
        {"seconds_per_selection", seconds},
        {"bits_per_minute",
         bci::wolpawBits(choices, static_cast<double>(right) / made) * 60.0 / seconds}};
  };
  nlohmann::json all = nullptr;
  if (completed > 0 && objects_made > 0 && cells_made > 0) {
    const double bits =
        completed *
        (bci::wolpawBits(object_choices, static_cast<double>(objects_right) / objects_made) +
         bci::wolpawBits(cell_choices, static_cast<double>(cells_right) / cells_made));
    all = {{"completed_trials", completed},
           {"seconds_per_trial", trial_seconds / completed},
           {"seconds_per_selection", trial_seconds / (2 * completed)},
           {"bits_per_minute", bits / trial_seconds * 60.0}};
  }
  return {{"trials", trials},
          {"objects", rate(object_choices, objects_right, objects_made, object_seconds)},
          {"cells", rate(cell_choices, cells_right, cells_made, cell_seconds)},
          {"all_inclusive", all}};
}

}  // namespace arbci::session
