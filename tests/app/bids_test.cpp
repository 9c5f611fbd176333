// A short session written as EEG-BIDS (`arbci run --bids`), an older session folder added to the
// same dataset (`arbci bids export`), then checked from outside: the official validator
// (bids-validator from npm, installed by scripts/install-deps) finds 0 errors, and MNE reads the
// recording and its events and finds the P300 of the simulated subject.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/run_process.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

namespace fs = std::filesystem;
const std::string kArbci = ARBCI_EXECUTABLE;

int lines(const std::string& text, const std::string& prefix) {
  int n = 0;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) n += line.rfind(prefix, 0) == 0 ? 1 : 0;
  return n;
}

TEST(Bids, ASessionExportPassesTheValidatorAndMneFindsTheP300) {
  ASSERT_TRUE(fs::exists(BIDS_VALIDATOR))
      << BIDS_VALIDATOR << " is missing: scripts/install-deps installs it (npm)";
  const fs::path dir = freshTempPath("bids_test", "export");
  fs::create_directories(dir);
  const fs::path root = dir / "bids";
  // A short calibration run (half the default's selections, each of all its sequences: 56
  // attended flashes with the trial's) and a quick arm: what is checked is the export.
  std::ofstream(dir / "session.json") << R"({
    "paradigm": {"calibration_selections": 4, "cue_s": 1.0, "pause_s": 0.5},
    "robot": {"speed_factor": 20}})";
  const ProcessResult run = runProcess(kArbci,
                                       {"run",
                                        "--headless",
                                        "--session",
                                        (dir / "session.json").string(),
                                        "--trials",
                                        "1",
                                        "--seed",
                                        "3",
                                        "--out",
                                        (dir / "session").string(),
                                        "--bids",
                                        root.string(),
                                        "--subject",
                                        "01",
                                        "--bids-session",
                                        "1",
                                        "--age",
                                        "34",
                                        "--sex",
                                        "F",
                                        "--handedness",
                                        "R"},
                                       600.0);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("BIDS: wrote"), std::string::npos) << run.out;
  const fs::path eeg = root / "sub-01" / "ses-1" / "eeg";
  const std::string stem = "sub-01_ses-1_task-arbci_run-1";
  for (const char* suffix :
       {"_eeg.bdf", "_eeg.json", "_channels.tsv", "_events.tsv", "_events.json"})
    EXPECT_TRUE(fs::exists(eeg / (stem + suffix))) << stem << suffix;
  EXPECT_TRUE(fs::exists(root / "derivatives" / "arbci" / "sub-01" / "ses-1" / "eeg" / stem /
                         "summary.json"));
  EXPECT_FALSE(fs::exists(root / "derivatives" / "arbci" / "sub-01" / "ses-1" / "eeg" / stem /
                          "robot.key"));  // the secret stays behind
  // The session folder's summary names the run the export chose, and the simulated subject.
  const auto summary = nlohmann::json::parse(fileBytes(dir / "session" / "summary.json"));
  EXPECT_EQ(summary["labels"]["run"], "1") << summary["labels"].dump();
  EXPECT_EQ(summary["bids"]["eeg_file"], (eeg / (stem + "_eeg.bdf")).string());
  EXPECT_NE(summary["eeg"]["source"].get<std::string>().find("simulated subject (seed "),
            std::string::npos)
      << summary["eeg"]["source"];

  // The events: every flash with T or N, and the robot's commands placed on the recording.
  const std::string events = fileBytes(eeg / (stem + "_events.tsv"));
  EXPECT_EQ(events.substr(0, events.find('\n')),
            "onset\tduration\ttrial_type\tvalue\tsample\tstimulus\ttarget\tdescription");
  EXPECT_NE(events.find("\tflash/target\t"), std::string::npos);
  EXPECT_NE(events.find("\tflash/nontarget\t"), std::string::npos);
  EXPECT_NE(events.find("\tT\tflash of object"), std::string::npos);
  EXPECT_NE(events.find("\trobot/command\t"), std::string::npos);
  EXPECT_NE(events.find("\tfeedback/"), std::string::npos);
  EXPECT_NE(events.find("sent GRASP"), std::string::npos);
  EXPECT_NE(events.find("\tselection\t"), std::string::npos);

  // The same folder again, as an older session: the next run, never over the first; a run given
  // that exists is refused.
  const ProcessResult again = runProcess(
      kArbci, {"bids", "export", (dir / "session").string(), root.string(), "--subject", "01",
               "--session", "1", "--author", "Ada Lovelace", "--author", "Alan Turing"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  // The subject as the run recorded them, described for a curator.
  EXPECT_EQ(fileBytes(root / "participants.tsv"),
            "participant_id\tage\tsex\thandedness\nsub-01\t34\tF\tR\n");
  EXPECT_TRUE(fs::exists(root / "participants.json"));
  EXPECT_NE(fileBytes(eeg / (stem + "_channels.tsv")).find("Photodiode\tTRIG\tuV"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(eeg / "sub-01_ses-1_task-arbci_run-2_eeg.bdf"));
  const ProcessResult taken =
      runProcess(kArbci, {"bids", "export", (dir / "session").string(), root.string(), "--subject",
                          "01", "--session", "1", "--run", "1"});
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_NE(taken.err.find("never overwritten"), std::string::npos) << taken.err;
  const ProcessResult bad = runProcess(
      kArbci, {"bids", "export", (dir / "session").string(), root.string(), "--subject", "0_1"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("letters and digits"), std::string::npos) << bad.err;

  // The official validator: 0 errors, 0 warnings.
  const ProcessResult validated = runProcess(BIDS_VALIDATOR, {root.string()}, 300.0);
  std::cout << validated.out;
  EXPECT_EQ(validated.exit_code, 0) << validated.out << validated.err;
  EXPECT_EQ(validated.out.find("[ERR]"), std::string::npos) << validated.out;
  EXPECT_EQ(validated.out.find("[WARN]"), std::string::npos) << validated.out;
  EXPECT_NE(validated.out.find("Summary"), std::string::npos) << validated.out;

  // MNE reads the recording and the events table: the attended flashes' average is positive at
  // Cz and Pz in 250-500 ms, and above the others'.
  const ProcessResult mne = runProcess(
      DEBIAN_PYTHON,
      {MNE_SCRIPT, (eeg / (stem + "_eeg.bdf")).string(), (eeg / (stem + "_events.tsv")).string()},
      300.0);
  ASSERT_EQ(mne.exit_code, 0) << mne.out << mne.err;
  std::cout << mne.out;
  EXPECT_EQ(lines(mne.out, "Cz ") + lines(mne.out, "Pz "), 2) << mne.out;
  std::istringstream in(mne.out);
  for (std::string name; in >> name;) {
    double target = 0.0, other = 0.0;
    in >> target >> other;
    EXPECT_GT(target, 0.0) << name;
    EXPECT_GT(target, other) << name;
    std::string rest;
    std::getline(in, rest);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arbci::test
