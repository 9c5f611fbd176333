// Writes an ARBCI session folder into an EEG-BIDS dataset (https://bids.neuroimaging.io): the
// recording as `sub-S/[ses-N/]eeg/sub-S[_ses-N]_task-T_run-R_eeg.bdf` with its `_eeg.json`,
// `_channels.tsv`, `_events.tsv` and `_events.json`; the dataset's `dataset_description.json`,
// `participants.tsv` and `README` (made when missing); and ARBCI's own files (summary, log,
// model, screenshots) under `derivatives/arbci/` beside the same entities. A run is never
// overwritten: without a run number the next free one is taken. Used by `arbci bids export` and
// `arbci run --bids`; docs/session.md describes the layout.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace arbci::app {

struct BidsEntities {
  std::string subject;         // letters and digits only
  std::string session;         // optional; letters and digits only
  std::string task = "arbci";  // letters and digits only
  std::string run;             // optional: the next free run when empty; digits only
};

// The subject's row in participants.tsv (participants.json describes the columns); empty: n/a.
struct BidsParticipant {
  std::string age;         // whole years, 0-150
  std::string sex;         // F, M or O
  std::string handedness;  // R, L or A
};

// What the sidecars say that the recording may not (one made before the session stated it).
struct BidsDescription {
  std::string reference;     // EEGReference; empty: the recording's (eeg.reference), else "n/a"
  std::string manufacturer;  // Manufacturer; empty: the recording's (eeg.manufacturer)
  std::vector<std::string> authors;  // the dataset's Authors; empty: left as they are
  BidsParticipant participant;       // empty fields: the session's summary.json labels
};

struct BidsExport {
  std::filesystem::path eeg_file;  // the BDF written
  std::string run;                 // the run number used
  size_t events = 0;
  std::vector<std::string> notes;  // what could not be exported, for the person
};

class BidsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws BidsError naming a label BIDS does not allow (checked before a run, so that its export
// cannot fail on a typo after the session).
void checkBidsEntities(const BidsEntities& entities);
// Throws BidsError naming a participant value participants.json does not describe.
void checkBidsParticipant(const BidsParticipant& participant);

// Where an export of `entities` into `root` goes: "sub-S/ses-N/eeg, run R" (R the next free run
// when entities.run is empty). Throws BidsError for a label BIDS does not allow.
std::string bidsTarget(const std::filesystem::path& root, const BidsEntities& entities);

// Throws BidsError with a message a person can act on (not a session folder, a label BIDS does
// not allow, a run that exists).
BidsExport exportToBids(const std::filesystem::path& session_dir, const std::filesystem::path& root,
                        const BidsEntities& entities, const BidsDescription& description = {});

}  // namespace arbci::app
