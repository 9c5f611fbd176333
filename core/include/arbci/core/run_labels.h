// Who and which run a session records: the subject, the session (a visit), the task and the run,
// as the experimenter gives them on the start screen (or on the command line), and what BIDS'
// participants.tsv says of the subject. They go into the session folder's summary.json and, with
// a BIDS root, name the run in the dataset and fill the subject's participants.tsv row.
#pragma once

#include <string>

namespace arbci::core {

struct RunLabels {
  std::string subject;  // letters and digits (BIDS)
  std::string session;  // optional
  std::string task = "arbci";
  std::string run;  // optional: empty for the next free run
  // The subject, as participants.tsv describes them; each optional (empty: n/a).
  std::string age;         // whole years
  std::string sex;         // F, M or O (other)
  std::string handedness;  // R, L or A (ambidextrous)
  bool operator==(const RunLabels&) const = default;
};

}  // namespace arbci::core
