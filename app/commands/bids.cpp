// `arbci bids export SESSION_DIR ROOT --subject S [--session N] [--task T] [--run R]`: writes a
// session folder into an EEG-BIDS dataset (app/bids/bids_export.h); `arbci run --bids` does the
// same at the end of a run.
#include <iostream>

#include "arbci/session/settings_schema.h"
#include "bids/bids_export.h"
#include "commands/bids_options.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/schema_option.h"

namespace arbci::app {

void addBidsOptions(CLI::App* command, BidsEntities& entities, BidsParticipant& participant,
                    std::string& root, bool root_option) {
  if (root_option)
    command->add_option("--bids", root,
                        "also write the session into this EEG-BIDS dataset when it ends "
                        "(needs --subject)");
  command->add_option("--subject", entities.subject, "BIDS subject label (letters and digits)");
  // `arbci run` has --session (the session file): there the BIDS session is --bids-session.
  command->add_option(root_option ? "--bids-session" : "--session", entities.session,
                      "BIDS session label (optional)");
  command->add_option("--task", entities.task, "BIDS task label")->capture_default_str();
  command->add_option("--run", entities.run,
                      "BIDS run number (default: the next free one; an existing run is never "
                      "overwritten)");
  command->add_option("--age", participant.age,
                      "the subject's age in whole years, for participants.tsv (optional)");
  command->add_option("--sex", participant.sex,
                      "the subject's sex for participants.tsv: F, M or O (optional)");
  command->add_option("--handedness", participant.handedness,
                      "the subject's handedness for participants.tsv: R, L or A (optional)");
}

void reportBidsExport(const BidsExport& done) {
  std::cout << "BIDS: wrote " << done.eeg_file.string() << " (run " << done.run << ", "
            << done.events << " events) with its sidecars; ARBCI's files under derivatives/arbci\n";
  for (const std::string& note : done.notes) std::cerr << "BIDS: " << note << "\n";
}

void addBidsCommand(CLI::App& root, int& exit_code) {
  CLI::App* bids = root.add_subcommand("bids", "EEG-BIDS datasets");
  bids->require_subcommand(1);
  struct Options {
    std::string session_dir, root;
    BidsEntities entities;
    BidsDescription description;
  };
  auto o = std::make_shared<Options>();
  CLI::App* out = bids->add_subcommand(
      "export",
      "Write an ARBCI session folder into an EEG-BIDS dataset: the recording as BDF with its\n"
      "_eeg.json, _channels.tsv, _events.tsv (every flash with T/N/U, phases, selections,\n"
      "feedback, robot commands and replies, ErrP verdicts) and _events.json; the dataset's\n"
      "dataset_description.json, participants.tsv (age, sex, handedness: given here or\n"
      "recorded on the start screen) with participants.json, and README; ARBCI's files under\n"
      "derivatives/arbci/. A run is never overwritten.");
  out->add_option("SESSION_DIR", o->session_dir, "the session folder (arbci run --out)")
      ->required();
  out->add_option("ROOT", o->root, "the BIDS dataset's folder (made when missing)")->required();
  std::string unused;
  addBidsOptions(out, o->entities, o->description.participant, unused, false);
  out->get_option("--subject")->required();
  schemaOption(*out, "--reference", o->description.reference, session::sessionKey("eeg.reference"),
               "for _eeg.json's EEGReference; not given: what the session recorded, else n/a");
  schemaOption(*out, "--manufacturer", o->description.manufacturer,
               session::sessionKey("eeg.manufacturer"),
               "for _eeg.json's Manufacturer; not given: what the session recorded");
  out->add_option("--author", o->description.authors,
                  "an author of the dataset, for dataset_description.json (repeat for each, in "
                  "order; replaces the Authors there)");
  out->callback([o, &exit_code] {
    try {
      reportBidsExport(exportToBids(o->session_dir, o->root, o->entities, o->description));
    } catch (const BidsError& error) {
      throw CliError(error.what());
    }
    exit_code = 0;
  });
}

}  // namespace arbci::app
