#include "arbci/session/paradigm/trial_book.h"

namespace arbci::session {

TrialRecord& TrialBook::at(int number) {
  number = std::max(1, number);
  while (static_cast<int>(trials_.size()) < number) {
    TrialRecord r;
    r.trial = static_cast<int>(trials_.size()) + 1;
    const TrialIntent& intent = intended_.at(static_cast<size_t>(r.trial - 1));
    r.intended_object = intent.object;
    r.intended_cell = {intent.row, intent.column};
    r.started_s = next_start_s_;
    trials_.push_back(r);
  }
  return trials_[static_cast<size_t>(number - 1)];
}

TrialRecord* TrialBook::find(int number) {
  if (number < 1 || number > static_cast<int>(trials_.size())) return nullptr;
  return &trials_[static_cast<size_t>(number - 1)];
}

const TrialRecord* TrialBook::find(int number) const {
  if (number < 1 || number > static_cast<int>(trials_.size())) return nullptr;
  return &trials_[static_cast<size_t>(number - 1)];
}

bool TrialBook::recordSelection(int number, const SelectionDecided& s) {
  TrialRecord& trial = at(number);
  if (s.objects) {
    trial.selected_object = s.object_id;
    trial.object_certainty = s.certainty;
    trial.object_flashes = s.flashes;
    trial.object_selection_s = s.selection_s;
    trial.object_interrupted_s = s.selection_interrupted_s;
  } else {
    trial.selected_cell = s.cell;
    trial.cell_certainty = s.certainty;
    trial.cell_flashes = s.flashes;
    trial.cell_selection_s = s.selection_s;
    trial.cell_interrupted_s = s.selection_interrupted_s;
  }
  const bool correct = s.objects ? trial.selected_object == trial.intended_object
                                 : trial.selected_cell == trial.intended_cell;
  SelectionMade made;
  made.object = s.objects;
  made.object_id = s.objects ? trial.selected_object : -1;
  made.cell = s.objects ? std::pair<int, int>{0, 0} : s.cell;
  made.correct = correct;
  trial.selections.push_back(made);
  return correct;
}

void TrialBook::markVerdict(int number, bool veto) {
  TrialRecord* trial = find(number);
  if (trial && !trial->selections.empty()) trial->selections.back().vetoed = veto;
}

void TrialBook::done(int number, double time_s, const std::string& why) {
  if (TrialRecord* trial = find(number)) {
    trial->ended_s = time_s;
    if (!why.empty())
      trial->outcome = trial->outcome == "incomplete" ? why : trial->outcome + "; " + why;
  }
  next_start_s_ = time_s;
}

}  // namespace arbci::session
