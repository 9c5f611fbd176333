// The online trials as the paradigm stage keeps them: each trial's record (its intention, the
// selections made and the ErrP's verdicts on them, where the robot went, how it ended), made when
// the paradigm first reaches the trial, and where the next trial's time starts.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arbci/session/session_config.h"
#include "arbci/session/trial_record.h"

namespace arbci::session {

// A selection as the paradigm decided it, for the trial's record.
struct SelectionDecided {
  bool objects = true;
  int object_id = -1;              // objects: the marker id selected
  std::pair<int, int> cell{0, 0};  // else: the cell
  double certainty = 0.0;
  int flashes = 0;
  double selection_s = 0.0;              // from its onsets as presented, without interruptions
  double selection_interrupted_s = 0.0;  // the time it stood interrupted
};

class TrialBook {
 public:
  explicit TrialBook(std::vector<TrialIntent> intended) : intended_(std::move(intended)) {}
  // Trial `number`'s record (a number below 1 is the first's), made with its intention when first
  // asked for (with every trial before it).
  TrialRecord& at(int number);
  // Trial `number`'s record, if it was made.
  TrialRecord* find(int number);
  const TrialRecord* find(int number) const;
  const std::vector<TrialRecord>& trials() const { return trials_; }
  // The next trial's time counts from `time_s` (the first's: from the end of training).
  void nextStartsAt(double time_s) { next_start_s_ = time_s; }

  // The selection made in trial `number`; returns whether it is the intended one.
  bool recordSelection(int number, const SelectionDecided& s);
  // The ErrP's verdict on trial `number`'s last selection.
  void markVerdict(int number, bool veto);
  // Trial `number` ended at `time_s`; `why`: ended by the experimenter (skipped, resumed after a
  // stop), added to its outcome.
  void done(int number, double time_s, const std::string& why);

 private:
  std::vector<TrialIntent> intended_;
  std::vector<TrialRecord> trials_;
  double next_start_s_ = 0.0;
};

}  // namespace arbci::session
