#include "bids/bids_export.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "arbci/bci/recording.h"
#include "bids/bids_events.h"

namespace arbci::app {
namespace fs = std::filesystem;
namespace {

// The BIDS version the files follow.
constexpr const char* kBidsVersion = "1.8.0";

void checkLabel(const std::string& what, const std::string& label, bool digits_only) {
  const bool ok = !label.empty() && std::all_of(label.begin(), label.end(), [&](unsigned char c) {
    return digits_only ? std::isdigit(c) : std::isalnum(c);
  });
  if (!ok)
    throw BidsError(
        "the " + what + " label \"" + label + "\" is not allowed in BIDS: use " +
        (digits_only ? "digits only (e.g. 1)" : "letters and digits only (e.g. 01, P3)"));
}

// Checked after the flush: a full disk shows only when the buffer reaches it.
void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw BidsError("cannot write " + path.string() + ": " + std::strerror(errno));
}

std::string number(double value) {
  std::ostringstream s;
  s << std::setprecision(10) << value;
  return s.str();
}

// A TSV cell: tabs and line breaks would break the table.
std::string cell(std::string s) {
  for (char& c : s) {
    if (c == '\t' || c == '\n' || c == '\r') c = ' ';
  }
  return s.empty() ? "n/a" : s;
}

// The numbers of the runs already in `eeg_dir` for these entities.
std::set<int> existingRuns(const fs::path& eeg_dir, const std::string& stem_prefix) {
  std::set<int> runs;
  if (!fs::is_directory(eeg_dir)) return runs;
  const std::regex pattern(
      std::regex_replace(stem_prefix, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
      "_run-([0-9]+)_eeg\\.bdf");
  for (const auto& entry : fs::directory_iterator(eeg_dir)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, m, pattern)) runs.insert(std::stoi(m[1].str()));
  }
  return runs;
}

// A dataset's dataset_description.json, when it has none; `authors` (when given) set in it
// either way.
void describeDataset(const fs::path& dir, const std::string& name, const std::string& type,
                     const std::vector<std::string>& authors = {}) {
  const fs::path file = dir / "dataset_description.json";
  if (fs::exists(file)) {
    if (authors.empty()) return;
    std::ifstream in(file);
    nlohmann::ordered_json d = nlohmann::ordered_json::parse(in, nullptr, false);
    if (d.is_discarded() || !d.is_object())
      throw BidsError(file.string() + " is not a JSON object: cannot set its Authors");
    d["Authors"] = authors;
    writeText(file, d.dump(2) + "\n");
    return;
  }
  fs::create_directories(dir);
  nlohmann::ordered_json d;
  d["Name"] = name;
  d["BIDSVersion"] = kBidsVersion;
  d["DatasetType"] = type;
  if (!authors.empty()) d["Authors"] = authors;
  d["GeneratedBy"] = {{{"Name", "ARBCI"}, {"Version", ARBCI_VERSION}}};
  writeText(file, d.dump(2) + "\n");
}

// participants.tsv's columns, as participants.json describes them.
constexpr const char* kParticipantColumns[] = {"participant_id", "age", "sex", "handedness"};

std::string participantsJson() {
  nlohmann::ordered_json j;
  j["participant_id"] = {{"Description", "the participant's label, as in the sub- folders"}};
  j["age"] = {{"Description", "age of the participant at the recording"}, {"Units", "year"}};
  j["sex"] = {{"Description", "sex of the participant, as they reported it"},
              {"Levels", {{"F", "female"}, {"M", "male"}, {"O", "other"}}}};
  j["handedness"] = {{"Description", "handedness of the participant, as they reported it"},
                     {"Levels", {{"R", "right"}, {"L", "left"}, {"A", "ambidextrous"}}}};
  return j.dump(2) + "\n";
}

std::vector<std::string> splitTabs(const std::string& line) {
  std::vector<std::string> cells;
  std::istringstream in(line);
  for (std::string c; std::getline(in, c, '\t');) cells.push_back(c);
  return cells;
}

// The subject's row in participants.tsv: added when missing; a cell that is n/a filled from
// `participant`, a stated one never changed. A table of an older export (participant_id only)
// gains the columns, n/a for the subjects already there; columns a curator added are kept.
void recordParticipant(const fs::path& root, const std::string& subject,
                       const BidsParticipant& participant) {
  const fs::path file = root / "participants.tsv";
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  if (std::ifstream in(file); in) {
    std::string line;
    if (std::getline(in, line)) header = splitTabs(line);
    while (std::getline(in, line))
      if (!line.empty()) rows.push_back(splitTabs(line));
  }
  if (header.empty() || header[0] != "participant_id") {
    if (!header.empty())
      throw BidsError(file.string() +
                      " does not start with a participant_id column: fix it by hand");
    header.push_back("participant_id");
  }
  for (const char* column : kParticipantColumns)
    if (std::find(header.begin(), header.end(), column) == header.end()) header.push_back(column);
  const auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (auto& row : rows) row.resize(header.size(), "n/a");
  const std::string id = "sub-" + subject;
  auto row = std::find_if(rows.begin(), rows.end(), [&](const auto& r) { return r[0] == id; });
  if (row == rows.end()) {
    rows.push_back(std::vector<std::string>(header.size(), "n/a"));
    rows.back()[0] = id;
    row = rows.end() - 1;
  }
  const std::pair<const char*, std::string> given[] = {
      {"age", participant.age}, {"sex", participant.sex}, {"handedness", participant.handedness}};
  for (const auto& [name, value] : given) {
    std::string& c = (*row)[column(name)];
    if ((c.empty() || c == "n/a") && !value.empty()) c = value;
  }
  std::ostringstream out;
  const auto line = [&out](const std::vector<std::string>& cells) {
    for (size_t i = 0; i < cells.size(); ++i) out << (i ? "\t" : "") << cell(cells[i]);
    out << "\n";
  };
  line(header);
  for (const auto& r : rows) line(r);
  writeText(file, out.str());
  if (!fs::exists(root / "participants.json"))
    writeText(root / "participants.json", participantsJson());
}

void ensureDatasetFiles(const fs::path& root, const std::string& subject,
                        const BidsDescription& description) {
  describeDataset(root, "ARBCI sessions", "raw", description.authors);
  if (!fs::exists(root / "README"))
    writeText(root / "README",
              "EEG of augmented-reality P300 brain-computer interface sessions recorded with "
              "ARBCI: objects on a table flash in a video see-through head-mounted display, the "
              "subject attends one, a robot arm moves it to a grid cell selected the same way.\n"
              "Each run's events table lists every flash (T attended, N not, U unknown), the "
              "phases, selections, feedback, robot commands and error-potential verdicts.\n"
              "ARBCI's own files for each run (summary, log, model, screenshots) are under "
              "derivatives/arbci/.\n");
  recordParticipant(root, subject, description.participant);
  describeDataset(root / "derivatives" / "arbci", "ARBCI session files", "derivative");
}

std::string parameter(const bci::Recording& r, const std::string& key) {
  const auto found = r.parameters.find(key);
  return found == r.parameters.end() ? "" : found->second;
}

// The BDF's length as every reader sees it: its records, the last one completed with zeros.
double bdfSeconds(const fs::path& bdf) {
  std::ifstream in(bdf, std::ios::binary);
  char header[256] = {};
  in.read(header, sizeof header);
  try {
    return std::stod(std::string(header + 236, 8)) * std::stod(std::string(header + 244, 8));
  } catch (const std::exception&) {
    throw BidsError(bdf.string() + ": its header gives no record count and duration");
  }
}

std::string eegSidecar(const bci::Recording& r, const std::string& task, int triggers,
                       const BidsDescription& description, double file_seconds) {
  nlohmann::ordered_json j;
  j["TaskName"] = task;
  j["TaskDescription"] =
      "P300 selection in augmented reality: objects, then grid rows and columns, flash in a "
      "head-mounted display; the subject attends the object to move and the cell to put it on.";
  j["Instructions"] = "Attend the cued (calibration) or chosen object and count its flashes.";
  j["SamplingFrequency"] = r.info.rate_hz;
  // What the export was given, else what the session recorded.
  auto stated = [&](const std::string& given, const std::string& key) {
    return given.empty() ? parameter(r, key) : given;
  };
  const std::string reference = stated(description.reference, "EegReference");
  j["EEGReference"] = reference.empty() ? "n/a" : reference;
  const std::string line = parameter(r, "PowerLineHz");
  double line_hz = 0.0;
  try {
    line_hz = line.empty() ? 0.0 : std::stod(line);
  } catch (const std::exception&) {
  }
  if (line_hz > 0.0) {
    j["PowerLineFrequency"] = line_hz;
  } else {
    j["PowerLineFrequency"] = "n/a";
  }
  j["SoftwareFilters"] = "n/a";  // the recording is unfiltered; the online filter is ARBCI's own
  const std::string source = parameter(r, "EegSource");
  const std::string manufacturer = stated(description.manufacturer, "EegManufacturer");
  // A maker or "n/a", as BIDS reads it (the validator takes no key of ARBCI's own in the
  // sidecar): where the signal came from is said in SoftwareVersions, the software that made it.
  j["Manufacturer"] = !manufacturer.empty() ? manufacturer : "n/a";
  j["SoftwareVersions"] = std::string("ARBCI ") + ARBCI_VERSION +
                          (source.empty() || source == "simulated"
                               ? " (simulated subject: the EEG was generated, no amplifier)"
                               : " (recording software; EEG source: " + source + ")");
  j["EEGChannelCount"] = r.info.channelCount() - triggers;
  j["TriggerChannelCount"] = triggers;
  // The data file's length (what a reader of the BDF gets); the zeros after the signal's end are
  // a "padding" event.
  j["RecordingDuration"] = file_seconds;
  j["RecordingType"] = "continuous";
  return j.dump(2) + "\n";
}

}  // namespace

void checkBidsEntities(const BidsEntities& entities) {
  checkLabel("subject", entities.subject, false);
  if (!entities.session.empty()) checkLabel("session", entities.session, false);
  checkLabel("task", entities.task, false);
  if (!entities.run.empty()) checkLabel("run", entities.run, true);
}

void checkBidsParticipant(const BidsParticipant& p) {
  if (!p.age.empty()) {
    const bool digits =
        p.age.size() <= 3 &&
        std::all_of(p.age.begin(), p.age.end(), [](unsigned char c) { return std::isdigit(c); });
    if (!digits || std::stoi(p.age) > 150)
      throw BidsError("the age \"" + p.age + "\" is not a whole number of years (0-150)");
  }
  const auto oneOf = [](const std::string& what, const std::string& value,
                        const std::string& levels, const std::string& meaning) {
    if (!value.empty() && (value.size() != 1 || levels.find(value) == std::string::npos))
      throw BidsError("the " + what + " \"" + value + "\" is not one of " + meaning);
  };
  oneOf("sex", p.sex, "FMO", "F, M, O (female, male, other) or empty");
  oneOf("handedness", p.handedness, "RLA", "R, L, A (right, left, ambidextrous) or empty");
}

namespace {

// Where an export goes, and the run it takes.
struct Layout {
  fs::path relative, eeg_dir;
  std::string prefix;
  std::set<int> runs;  // those already there
  int run = 1;
};

Layout layoutOf(const fs::path& root, const BidsEntities& entities) {
  Layout l;
  const std::string sub = "sub-" + entities.subject;
  const std::string ses = entities.session.empty() ? "" : "ses-" + entities.session;
  l.relative = ses.empty() ? fs::path(sub) : fs::path(sub) / ses;
  l.eeg_dir = root / l.relative / "eeg";
  l.prefix = sub + (ses.empty() ? "" : "_" + ses) + "_task-" + entities.task;
  l.runs = existingRuns(l.eeg_dir, l.prefix);
  l.run =
      entities.run.empty() ? (l.runs.empty() ? 1 : *l.runs.rbegin() + 1) : std::stoi(entities.run);
  return l;
}

}  // namespace

std::string bidsTarget(const fs::path& root, const BidsEntities& entities) {
  checkBidsEntities(entities);
  const Layout l = layoutOf(root, entities);
  std::string text =
      (l.relative / "eeg").string() + ", " + l.prefix + ", run " + std::to_string(l.run);
  if (entities.run.empty()) text += " (the next free)";
  if (l.runs.count(l.run)) text += ": already there; runs are never overwritten";
  return text;
}

BidsExport exportRun(const bci::Recording& recording, const fs::path& session_dir,
                     const fs::path& root, const Layout& layout, const std::string& stem,
                     const BidsEntities& entities, const BidsDescription& description);

BidsExport exportToBids(const fs::path& session_dir, const fs::path& root,
                        const BidsEntities& entities, const BidsDescription& description) {
  checkBidsEntities(entities);
  const fs::path bdf = session_dir / "recording.bdf";
  if (!fs::exists(bdf))
    throw BidsError("no recording.bdf in " + session_dir.string() +
                    ": give an ARBCI session folder (the --out of arbci run)");
  bci::Recording recording;
  try {
    recording = bci::readRecording(bdf);
  } catch (const std::exception& error) {
    throw BidsError("cannot read " + bdf.string() + ": " + error.what());
  }
  const Layout layout = layoutOf(root, entities);
  const fs::path& eeg_dir = layout.eeg_dir;
  const std::string& prefix = layout.prefix;
  const std::set<int>& runs = layout.runs;
  const int run = layout.run;
  if (runs.count(run))
    throw BidsError("run " + std::to_string(run) + " of " + prefix + " is already in " +
                    root.string() + "; runs are never overwritten (leave --run out for the next, " +
                    std::to_string(*runs.rbegin() + 1) + ")");
  BidsDescription described = description;
  BidsParticipant& participant = described.participant;
  {
    // Unless the export was given them, what the start screen (or --age ...) recorded.
    std::ifstream in(session_dir / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    if (summary.is_object() && summary.contains("labels") && summary["labels"].is_object()) {
      const nlohmann::json& l = summary["labels"];
      if (participant.age.empty()) participant.age = l.value("age", "");
      if (participant.sex.empty()) participant.sex = l.value("sex", "");
      if (participant.handedness.empty()) participant.handedness = l.value("handedness", "");
    }
  }
  checkBidsParticipant(participant);
  ensureDatasetFiles(root, entities.subject, described);
  fs::create_directories(eeg_dir);
  const std::string stem = prefix + "_run-" + std::to_string(run);
  try {
    return exportRun(recording, session_dir, root, layout, stem, entities, described);
  } catch (const std::exception& error) {
    // A run half exported (a full disk) would block its own export later ("already in"): what
    // was written of it goes, so that the same command can be run again once there is room.
    std::error_code ignored;
    for (const auto& entry : fs::directory_iterator(eeg_dir, ignored)) {
      if (entry.path().filename().string().rfind(stem + "_", 0) == 0)
        fs::remove(entry.path(), ignored);
    }
    fs::remove_all(root / "derivatives" / "arbci" / layout.relative / "eeg" / stem, ignored);
    throw BidsError(std::string(error.what()) + "; nothing of run " + std::to_string(run) +
                    " was left in " + root.string() + ": make room and export it again");
  }
}

// The run's files, once its layout is settled; throws on the first that cannot be written.
BidsExport exportRun(const bci::Recording& recording, const fs::path& session_dir,
                     const fs::path& root, const Layout& layout, const std::string& stem,
                     const BidsEntities& entities, const BidsDescription& description) {
  const fs::path& eeg_dir = layout.eeg_dir;
  const fs::path bdf = session_dir / "recording.bdf";
  const int run = layout.run;
  BidsExport out;
  out.run = std::to_string(run);
  out.eeg_file = eeg_dir / (stem + "_eeg.bdf");
  fs::copy_file(bdf, out.eeg_file, fs::copy_options::none);

  // Channels: EEG in microvolts; the photodiode a TRIG channel, as BIDS types an analog trigger
  // (MNE reads it as a stim channel, in the volts its BDF unit gives, so its unit does not
  // change on reading), in the unit the BDF gives every channel.
  const std::string photodiode = parameter(recording, "PhotodiodeChannel");
  std::ostringstream channels;
  channels << "name\ttype\tunits\tstatus\tstatus_description\n";
  int triggers = 0;
  for (const std::string& name : recording.info.channels) {
    const bool is_photodiode = name == photodiode || name == "Photodiode";
    triggers += is_photodiode ? 1 : 0;
    channels << cell(name) << "\t" << (is_photodiode ? "TRIG" : "EEG") << "\t"
             << "uV"
             << "\tgood\t"
             << (is_photodiode ? "photodiode on the display: the flashes' presented onsets" : "n/a")
             << "\n";
  }
  writeText(eeg_dir / (stem + "_channels.tsv"), channels.str());
  const double file_seconds = bdfSeconds(out.eeg_file);
  writeText(eeg_dir / (stem + "_eeg.json"),
            eegSidecar(recording, entities.task, triggers, description, file_seconds));

  BidsEvents events = sessionEvents(recording, session_dir / "log.jsonl");
  if (const double padded = file_seconds - recording.seconds();
      padded > 0.5 / recording.info.rate_hz) {
    BidsEvent e;
    e.sample = recording.samples;
    e.onset_s = recording.seconds();
    e.duration_s = padded;
    e.trial_type = "padding";
    e.value = e.stimulus = e.target = "n/a";
    e.description = "zeros completing the BDF's last record: the signal ends here";
    events.rows.push_back(e);
  }
  std::ostringstream table;
  table << "onset\tduration\ttrial_type\tvalue\tsample\tstimulus\ttarget\tdescription\n";
  for (const BidsEvent& e : events.rows) {
    table << number(e.onset_s) << "\t" << number(e.duration_s) << "\t" << cell(e.trial_type) << "\t"
          << cell(e.value) << "\t" << e.sample << "\t" << cell(e.stimulus) << "\t" << cell(e.target)
          << "\t" << cell(e.description) << "\n";
  }
  writeText(eeg_dir / (stem + "_events.tsv"), table.str());
  writeText(eeg_dir / (stem + "_events.json"), eventsSidecar());
  out.events = events.rows.size();
  out.notes = events.notes;

  // ARBCI's own files, beside the same entities in the derivatives dataset.
  const fs::path own = root / "derivatives" / "arbci" / layout.relative / "eeg" / stem;
  fs::create_directories(own);
  for (const auto& entry : fs::directory_iterator(session_dir)) {
    const std::string name = entry.path().filename().string();
    const bool wanted = name == "summary.json" || name == "log.jsonl" || name == "model.json" ||
                        name == "session.json" || name == "robotd.log" ||
                        (name.rfind("hmd_", 0) == 0 && entry.path().extension() == ".png");
    if (wanted && entry.is_regular_file()) fs::copy_file(entry.path(), own / name);
  }
  return out;
}

}  // namespace arbci::app
