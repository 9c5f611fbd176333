#include "arbci/session/trial_record.h"

#include <cstdio>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/intervals.h"

namespace arbci::session {

std::optional<int> TrialRecord::acceptedObject() const {
  std::optional<int> out;
  for (const SelectionMade& s : selections)
    if (s.object && !s.vetoed.value_or(false)) out = s.object_id;
  return out;
}

std::optional<std::pair<int, int>> TrialRecord::acceptedCell() const {
  std::optional<std::pair<int, int>> out;
  for (const SelectionMade& s : selections)
    if (!s.object && !s.vetoed.value_or(false)) out = s.cell;
  return out;
}

int TrialRecord::wrongRobotActions() const {
  return (robot_object && *robot_object != intended_object) +
         (robot_cell && *robot_cell != intended_cell);
}

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

namespace {

nlohmann::json interruptionsJson(const std::vector<TrialRecord::Interruption>& all) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& i : all) {
    out.push_back({{"kind", i.kind},
                   {"at_s", i.at_s},
                   {"resumed_s",
                    i.resumed_s >= 0.0 ? nlohmann::json(i.resumed_s) : nlohmann::json(nullptr)}});
  }
  return out;
}

nlohmann::json orNull(double v) {
  return v >= 0.0 ? nlohmann::json(v) : nlohmann::json(nullptr);
}
nlohmann::json cellJson(const std::optional<std::pair<int, int>>& c) {
  return c ? nlohmann::json{c->first, c->second} : nlohmann::json(nullptr);
}
nlohmann::json idJson(const std::optional<int>& id) {
  return id ? nlohmann::json(*id) : nlohmann::json(nullptr);
}

// One trial's entry in the summary's "trials".
nlohmann::json trialJson(const TrialRecord& t) {
  nlohmann::json selections = nlohmann::json::array();
  for (const SelectionMade& s : t.selections) {
    nlohmann::json one = {{"kind", s.object ? "object" : "cell"},
                          {"correct", s.correct},
                          {"vetoed", s.vetoed ? nlohmann::json(*s.vetoed) : nullptr}};
    if (s.object)
      one["object"] = s.object_id;
    else
      one["cell"] = {s.cell.first, s.cell.second};
    selections.push_back(one);
  }
  return {
      {"trial", t.trial},
      {"intended_object", t.intended_object},
      {"selected_object", idJson(t.acceptedObject())},
      {"intended_cell", {t.intended_cell.first, t.intended_cell.second}},
      {"selected_cell", cellJson(t.acceptedCell())},
      {"selections", selections},
      {"robot",
       {{"object", idJson(t.robot_object)},
        {"cell", cellJson(t.robot_cell)},
        {"returned", t.robot_returned},
        {"pose_age_max_s", t.grasp_pose_age_max_s ? nlohmann::json(*t.grasp_pose_age_max_s)
                                                  : nlohmann::json(nullptr)}}},
      {"object_flashes", t.object_flashes},
      {"cell_flashes", t.cell_flashes},
      {"object_selection_s", t.object_selection_s},
      {"cell_selection_s", t.cell_selection_s},
      {"object_interrupted_s", t.object_interrupted_s},
      {"cell_interrupted_s", t.cell_interrupted_s},
      {"interruptions", interruptionsJson(t.interruptions)},
      {"outcome", t.outcome},
      {"duration_s", t.ended_s >= 0.0 ? orNull(t.ended_s - t.started_s) : nlohmann::json(nullptr)},
      {"placement_error_m", orNull(t.placement_error_m)},
      {"arm_held", t.arm_held},
      {"post_hoc_object", idJson(t.post_hoc_object)},
      {"frozen_object", idJson(t.frozen_object)}};
}

// Accuracy, seconds per selection and bits per minute of one kind of selection (null: none made).
nlohmann::json rate(int choices, int right, int made, double total_seconds) {
  if (made == 0) return nlohmann::json(nullptr);
  const double seconds = total_seconds / made;
  const bci::Interval interval = bci::wilsonInterval(right, made);
  return nlohmann::json{
      {"accuracy", static_cast<double>(right) / made},
      {"right", right},
      {"of", made},
      {"accuracy_interval", {interval.low, interval.high}},
      {"seconds_per_selection", seconds},
      {"bits_per_minute",
       bci::wolpawBits(choices, static_cast<double>(right) / made) * 60.0 / seconds}};
}

}  // namespace

nlohmann::json trialsSummary(const std::vector<TrialRecord>& records, int object_choices,
                             int cell_choices) {
  nlohmann::json trials = nlohmann::json::array();
  int objects_right = 0, cells_right = 0, objects_made = 0, cells_made = 0, completed = 0;
  double object_seconds = 0, cell_seconds = 0, trial_seconds = 0;
  int wrong_robot_actions = 0, post_hoc_right = 0, post_hoc_made = 0;
  nlohmann::json first_right = nullptr;
  for (const TrialRecord& t : records) {
    if (first_right.is_null() && t.ended_s >= 0.0 && t.robot_object == t.intended_object &&
        t.robot_cell == t.intended_cell && !t.robot_returned)
      first_right = t.ended_s;
    wrong_robot_actions += t.wrongRobotActions();
    if (t.post_hoc_object) {
      ++post_hoc_made;
      post_hoc_right += *t.post_hoc_object == t.intended_object;
    }
    trials.push_back(trialJson(t));
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
  // The online trials' objects as decided after the run: by the last fit where the session
  // learnt from use; else by the model that decided them online, so the same as online. Either
  // way these, not the calibration run's in-sample figures, say how the model did on new data.
  nlohmann::json post_hoc = {{"scored_by", "the model that decided them online"},
                             {"objects", {{"right", objects_right}, {"of", objects_made}}}};
  if (post_hoc_made > 0)
    post_hoc = {{"scored_by", "the last fit learnt from use"},
                {"objects", {{"right", post_hoc_right}, {"of", post_hoc_made}}}};
  const auto& counts = post_hoc["objects"];
  const bci::Interval interval =
      bci::wilsonInterval(counts["right"].get<int>(), counts["of"].get<int>());
  post_hoc["objects"]["accuracy_interval"] = {interval.low, interval.high};
  return {{"trials", trials},
          {"post_hoc", post_hoc},
          {"wrong_robot_actions", wrong_robot_actions},
          {"objects", rate(object_choices, objects_right, objects_made, object_seconds)},
          {"cells", rate(cell_choices, cells_right, cells_made, cell_seconds)},
          {"all_inclusive", all},
          {"first_right_placement_s", first_right}};
}

}  // namespace arbci::session
