// The rows of a BIDS `_events.tsv` for an ARBCI session: every flash (its stimulus code, what
// the code stands for, T/N/U), every annotation of the recording (phases, selections, feedback,
// tracking, the session's end) at its sample, and what only the session's log holds (robot
// commands and replies, ErrP decisions and corrections, placements), placed on the recording's
// time through the phase changes that both record.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "arbci/bci/recording.h"

namespace arbci::app {

struct BidsEvent {
  double onset_s = 0.0;     // from the recording's first sample
  double duration_s = 0.0;  // 0 when instantaneous
  std::string trial_type;   // kind/condition: flash/target, feedback/error, ... (eventsSidecar)
  std::string value;        // a flash's stimulus code; "n/a" otherwise
  std::int64_t sample = 0;  // the recording's sample at the onset
  std::string stimulus;     // a flash: "object 10", "row 2", ...; "n/a" otherwise
  std::string target;       // a flash: T (attended), N, or U (unknown); "n/a" otherwise
  std::string description;  // what happened, in words
};

struct BidsEvents {
  std::vector<BidsEvent> rows;  // ordered by onset
  // What could not be placed (a log without phase changes to align with), for the person.
  std::vector<std::string> notes;
};

// `log` may be missing (an older folder): the recording's events only, and a note.
BidsEvents sessionEvents(const bci::Recording& recording, const std::filesystem::path& log);

// The `_events.json` sidecar describing the columns and their levels.
std::string eventsSidecar();

}  // namespace arbci::app
