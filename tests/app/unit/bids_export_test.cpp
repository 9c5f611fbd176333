// The BIDS export on a session folder made here (a recording with known events, a log with a
// robot command), in process: trial_type carries each event's condition (flash/target,
// flash/nontarget, feedback/error, ...), the photodiode's unit is the BDF's, RecordingDuration
// is the BDF's length with the zeros after the signal an event of their own, and the reference,
// manufacturer and authors are the session's or the command's. (The validator and MNE read a
// whole session's export in tests/app/bids_test.cpp.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "arbci/bci/recording_writer.h"
#include "bids/bids_export.h"
#include "support/file_size_limit.h"
#include "support/test_files.h"

namespace arbci::app {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// 10.1 s at 256 Hz (2,585 samples: the last 0.25 s record is padded), Cz and a photodiode.
fs::path sessionFolder(const std::string& name, const std::string& reference) {
  const fs::path dir = test::freshTempPath("bids_export", name);
  fs::create_directories(dir);
  bci::SignalInfo info;
  info.rate_hz = 256.0;
  info.channels = {"Cz", "Photodiode"};
  {
    bci::RecordingWriter writer(dir / "recording.bdf", info,
                                {{"PhotodiodeChannel", "Photodiode"},
                                 {"EegSource", "rda"},
                                 {"EegReference", reference},
                                 {"StimulusCodeMap", "1=object 10;2=object 20"}});
    bci::Block block(0, 2, 2585);
    writer.write(block);
    writer.addStimulus({256, 1, true, 17, true});
    writer.addStimulus({307, 2, false, 17, true});
    writer.addStimulus({358, 2, false, 17, false});
    writer.addAnnotation({10, "Phase calibration", 0});
    writer.addAnnotation({600, "Feedback 2 error", 0});
    writer.addAnnotation({700, "ErrP rejected the selection (posterior of error 0.91)", 0});
    writer.addAnnotation({800, "Stimulus/S  1", 0});
    writer.addAnnotation({900, "Lost 24 samples: gap in the source's samples", 24});
  }
  std::ofstream(dir / "log.jsonl") << R"({"t": 0.04, "event": "phase", "phase": "calibration"})"
                                   << "\n"
                                   << R"({"t": 3.0, "event": "robot_command", "command": "GRASP",)"
                                   << R"( "object": 10, "sequence": 1})"
                                   << "\n";
  return dir;
}

std::map<std::string, int> trialTypes(const std::string& events) {
  std::map<std::string, int> out;
  std::istringstream in(events);
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    std::istringstream cells(line);
    std::string onset, duration, type;
    std::getline(cells, onset, '\t');
    std::getline(cells, duration, '\t');
    std::getline(cells, type, '\t');
    ++out[type];
  }
  return out;
}

TEST(BidsExport, TrialTypeCarriesEachEventsCondition) {
  const fs::path dir = sessionFolder("conditions", "FCz");
  const fs::path root = dir / "bids";
  const BidsExport done = exportToBids(dir, root, {"01", "", "arbci", ""});
  const std::string events =
      read(done.eeg_file.parent_path() / "sub-01_task-arbci_run-1_events.tsv");
  const std::map<std::string, int> expected{
      {"flash/target", 1},   {"flash/nontarget", 1}, {"flash/unlabelled", 1}, {"phase", 1},
      {"feedback/error", 1}, {"errp/rejected", 1},   {"amplifier_marker", 1}, {"data_loss", 1},
      {"robot/command", 1},  {"padding", 1}};
  EXPECT_EQ(trialTypes(events), expected) << events;
  // Each level is described in the sidecar.
  const nlohmann::json sidecar = nlohmann::json::parse(
      read(done.eeg_file.parent_path() / "sub-01_task-arbci_run-1_events.json"));
  for (const auto& [level, count] : expected)
    EXPECT_TRUE(sidecar["trial_type"]["Levels"].contains(level)) << level;
}

TEST(BidsExport, TheDurationIsTheFilesAndThePaddingIsAnEvent) {
  const fs::path dir = sessionFolder("duration", "");
  const BidsExport done = exportToBids(dir, dir / "bids", {"01", "", "arbci", ""});
  const fs::path eeg = done.eeg_file.parent_path();
  const nlohmann::json sidecar =
      nlohmann::json::parse(read(eeg / "sub-01_task-arbci_run-1_eeg.json"));
  EXPECT_DOUBLE_EQ(sidecar["RecordingDuration"].get<double>(), 10.25);  // 41 records of 0.25 s
  EXPECT_EQ(sidecar["EEGReference"], "n/a");
  EXPECT_EQ(sidecar["Manufacturer"], "n/a");  // no maker stated: n/a, and the source apart
  EXPECT_EQ(sidecar["SoftwareVersions"],
            "ARBCI " ARBCI_VERSION " (recording software; EEG source: rda)");
  EXPECT_EQ(sidecar["EEGChannelCount"], 1);
  EXPECT_EQ(sidecar["TriggerChannelCount"], 1);
  const std::string events = read(eeg / "sub-01_task-arbci_run-1_events.tsv");
  EXPECT_NE(events.find("\t0.15234375\tpadding\tn/a\t2585\t"), std::string::npos) << events;
  const std::string channels = read(eeg / "sub-01_task-arbci_run-1_channels.tsv");
  EXPECT_NE(channels.find("Photodiode\tTRIG\tuV\t"), std::string::npos) << channels;
}

// The subject's row: from the session's summary.json labels (the start screen's age, sex and
// handedness), or the command's; a stated cell is never changed by a later export, an n/a one is
// filled; an older table (participant_id only) gains the columns; participants.json describes
// them; a value participants.json does not describe is refused.
TEST(BidsExport, TheParticipantsRowHoldsAgeSexAndHandedness) {
  const fs::path dir = sessionFolder("participants", "");
  const fs::path root = dir / "bids";
  fs::create_directories(root);
  std::ofstream(root / "participants.tsv") << "participant_id\nsub-00\n";
  std::ofstream(dir / "summary.json")
      << R"({"labels": {"subject": "01", "age": "34", "sex": "F", "handedness": ""}})";
  exportToBids(dir, root, {"01", "", "arbci", ""});
  EXPECT_EQ(read(root / "participants.tsv"),
            "participant_id\tage\tsex\thandedness\nsub-00\tn/a\tn/a\tn/a\nsub-01\t34\tF\tn/a\n");
  BidsDescription described;
  described.participant = {"35", "M", "L"};
  exportToBids(dir, root, {"01", "", "arbci", ""}, described);
  EXPECT_EQ(read(root / "participants.tsv"),
            "participant_id\tage\tsex\thandedness\nsub-00\tn/a\tn/a\tn/a\nsub-01\t34\tF\tL\n");
  const nlohmann::json columns = nlohmann::json::parse(read(root / "participants.json"));
  EXPECT_EQ(columns["age"]["Units"], "year");
  EXPECT_EQ(columns["sex"]["Levels"]["O"], "other");
  EXPECT_EQ(columns["handedness"]["Levels"]["A"], "ambidextrous");
  described.participant = {"", "X", ""};
  try {
    exportToBids(dir, root, {"02", "", "arbci", ""}, described);
    FAIL() << "a sex participants.json does not describe was taken";
  } catch (const BidsError& error) {
    EXPECT_NE(std::string(error.what()).find("F, M, O"), std::string::npos) << error.what();
  }
  EXPECT_THROW(checkBidsParticipant({"abc", "", ""}), BidsError);
  EXPECT_THROW(checkBidsParticipant({"200", "", ""}), BidsError);
  EXPECT_NO_THROW(checkBidsParticipant({"7", "O", "A"}));
}

TEST(BidsExport, ReferenceManufacturerAndAuthorsFromTheSessionOrTheCommand) {
  const fs::path dir = sessionFolder("described", "linked mastoids");
  const fs::path root = dir / "bids";
  BidsDescription described;
  described.manufacturer = "Brain Products";
  described.authors = {"Ada Lovelace", "Alan Turing"};
  const BidsExport done = exportToBids(dir, root, {"01", "", "arbci", ""}, described);
  const nlohmann::json sidecar =
      nlohmann::json::parse(read(done.eeg_file.parent_path() / "sub-01_task-arbci_run-1_eeg.json"));
  EXPECT_EQ(sidecar["EEGReference"], "linked mastoids");  // the session's
  EXPECT_EQ(sidecar["Manufacturer"], "Brain Products");   // the command's
  nlohmann::json dataset = nlohmann::json::parse(read(root / "dataset_description.json"));
  EXPECT_EQ(dataset["Authors"], nlohmann::json::array({"Ada Lovelace", "Alan Turing"}));
  // A later export with other authors replaces them; one without leaves them.
  described.authors = {"Grace Hopper"};
  exportToBids(dir, root, {"01", "", "arbci", ""}, described);
  exportToBids(dir, root, {"01", "", "arbci", ""});
  dataset = nlohmann::json::parse(read(root / "dataset_description.json"));
  EXPECT_EQ(dataset["Authors"], nlohmann::json::array({"Grace Hopper"}));
  EXPECT_EQ(dataset["Name"], "ARBCI sessions");
}

// A disk that fills during the export (a file-size limit fails the copy as a full disk does):
// the error says so, nothing of the run is left to block its export later, and the same export
// runs once there is room.
TEST(BidsExport, AFullDiskLeavesNoHalfRunAndTheSameExportWorksOnceThereIsRoom) {
  const fs::path dir = sessionFolder("full_disk", "");
  const fs::path root = dir / "bids";
  {
    test::FileSizeLimit limit(20 * 1024);
    try {
      exportToBids(dir, root, {"01", "", "arbci", ""});
      ADD_FAILURE() << "exported past the file-size limit";
    } catch (const BidsError& error) {
      EXPECT_NE(std::string(error.what()).find("nothing of run 1 was left in"), std::string::npos)
          << error.what();
    }
  }
  for (const auto& entry : fs::recursive_directory_iterator(root))
    EXPECT_EQ(entry.path().filename().string().find("run-1"), std::string::npos) << entry.path();
  const BidsExport done = exportToBids(dir, root, {"01", "", "arbci", ""});
  EXPECT_EQ(done.run, "1");
  EXPECT_TRUE(fs::exists(done.eeg_file));
}

}  // namespace
}  // namespace arbci::app
