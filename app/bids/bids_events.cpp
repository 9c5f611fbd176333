#include "bids/bids_events.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "arbci/core/text.h"

namespace arbci::app {
namespace {

// "1=object 10;2=object 20;...;101=row 1" (the recording's StimulusCodeMap) as code -> words.
std::map<int, std::string> codeMap(const bci::Recording& recording) {
  std::map<int, std::string> out;
  const auto found = recording.parameters.find("StimulusCodeMap");
  if (found == recording.parameters.end()) return out;
  std::stringstream in(found->second);
  std::string item;
  while (std::getline(in, item, ';')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) continue;
    try {
      out[std::stoi(item.substr(0, eq))] = item.substr(eq + 1);
    } catch (const std::exception&) {
    }
  }
  return out;
}

bool endsWith(const std::string& text, const std::string& end) {
  return text.size() >= end.size() && text.compare(text.size() - end.size(), end.size(), end) == 0;
}

// An annotation's condition from its words, as "kind/level" where a reader epochs by the level
// (MNE selects "feedback" for every "feedback/..."): "Feedback 3 error" is feedback/error.
std::string annotationType(const std::string& text) {
  const std::string first = core::lowerCase(text.substr(0, text.find(' ')));
  if (first == "selected") return "selection";
  if (first == "feedback") {
    for (const char* level : {"correct", "error"})
      if (endsWith(text, std::string(" ") + level)) return std::string("feedback/") + level;
    return "feedback/unknown";
  }
  if (first == "errp") {
    if (text.rfind("ErrP rejected", 0) == 0) return "errp/rejected";
    if (text.rfind("ErrP accepted", 0) == 0) return "errp/accepted";
  }
  if (first == "lost") return "data_loss";
  if (first == "phase" || first == "tracking" || first == "session") return first;
  // An amplifier's own marker ("Stimulus/S  1", from a trigger input).
  if (const auto slash = text.find('/');
      slash != std::string::npos && slash > 0 && text.find(' ') > slash)
    return "amplifier_marker";
  return "annotation";
}

// The log's session clock against the recording's: for each phase change both recorded, the
// recording's time minus the log's. A log event takes the offset of the nearest such pair.
class LogClock {
 public:
  LogClock(const bci::Recording& recording, const std::vector<nlohmann::json>& log) {
    std::vector<double> recorded, logged;
    for (const bci::Annotation& a : recording.annotations) {
      if (a.text.rfind("Phase ", 0) == 0)
        recorded.push_back(static_cast<double>(a.sample) / recording.info.rate_hz);
    }
    for (const nlohmann::json& e : log) {
      if (e.value("event", "") == "phase" && e.contains("t"))
        logged.push_back(e["t"].get<double>());
    }
    if (recorded.size() != logged.size()) return;  // not the same run's: nothing is placed
    for (size_t i = 0; i < logged.size(); ++i)
      pairs_.emplace_back(logged[i], recorded[i] - logged[i]);
  }
  bool usable() const { return !pairs_.empty(); }
  double recordingTime(double log_t) const {
    const auto nearest = std::min_element(pairs_.begin(), pairs_.end(), [&](auto& a, auto& b) {
      return std::abs(a.first - log_t) < std::abs(b.first - log_t);
    });
    return log_t + nearest->second;
  }

 private:
  std::vector<std::pair<double, double>> pairs_;  // (log time, recording minus log)
};

std::string describeLogEvent(const nlohmann::json& e) {
  const std::string event = e.value("event", "");
  if (event == "robot_command") {
    std::string text = "sent " + e.value("command", std::string("?"));
    if (e.contains("object")) text += " object " + e["object"].dump();
    if (e.contains("cell")) text += " cell " + e["cell"].dump();
    if (e.value("returning", false)) text += " (putting it back)";
    return text + " (sequence " + e.value("sequence", nlohmann::json(0)).dump() + ")";
  }
  if (event == "robot") {
    // Link events (connected, silent, restarted) belong to no command.
    const bool link = e.value("sequence", 0) == 0;
    std::string text =
        link ? "robot link " + e.value("kind", std::string(""))
             : e.value("command", std::string("")) + " " + e.value("kind", std::string(""));
    if (e.contains("outcome")) text += " " + e["outcome"].get<std::string>();
    if (e.contains("reason")) text += " (" + e["reason"].get<std::string>() + ")";
    const std::string detail = e.value("text", std::string(""));
    return detail.empty() ? text : text + ": " + detail;
  }
  if (event == "placement")
    return "placed object " + e.value("object", nlohmann::json(0)).dump() + " " +
           std::to_string(e.value("error_m", 0.0) * 1000.0) + " mm from the cell centre";
  nlohmann::json rest = e;
  rest.erase("t");
  rest.erase("event");
  return event + " " + rest.dump();
}

std::string logType(const std::string& event) {
  if (event == "robot_command") return "robot/command";
  if (event == "robot") return "robot/reply";
  if (event == "errp_decision") return "errp/decision";
  if (event == "errp_correction") return "errp/correction";
  if (event == "placement") return "placement";
  return "";
}

}  // namespace

BidsEvents sessionEvents(const bci::Recording& recording, const std::filesystem::path& log_path) {
  BidsEvents out;
  const double rate = recording.info.rate_hz;
  const auto codes = codeMap(recording);
  for (const bci::StimulusEvent& s : recording.stimuli) {
    BidsEvent e;
    e.sample = s.sample;
    e.onset_s = static_cast<double>(s.sample) / rate;
    e.duration_s = static_cast<double>(s.duration_samples) / rate;
    // The condition a reader epochs by (target against non-target), in trial_type itself.
    e.trial_type = !s.known ? "flash/unlabelled" : s.target ? "flash/target" : "flash/nontarget";
    e.value = std::to_string(s.code);
    const auto named = codes.find(s.code);
    e.stimulus = named != codes.end() ? named->second : "n/a";
    e.target = !s.known ? "U" : s.target ? "T" : "N";
    e.description = "flash of " + (named != codes.end() ? named->second : "code " + e.value);
    out.rows.push_back(e);
  }
  for (const bci::Annotation& a : recording.annotations) {
    if (a.text.rfind("Param ", 0) == 0) continue;  // the session's settings: in the _eeg.json
    BidsEvent e;
    e.sample = a.sample;
    e.onset_s = static_cast<double>(a.sample) / rate;
    e.duration_s = static_cast<double>(a.duration_samples) / rate;
    e.trial_type = annotationType(a.text);
    e.value = e.stimulus = e.target = "n/a";
    e.description = a.text;
    out.rows.push_back(e);
  }
  std::vector<nlohmann::json> log;
  if (std::ifstream in(log_path); in) {
    std::string line;
    while (std::getline(in, line)) {
      try {
        log.push_back(nlohmann::json::parse(line));
      } catch (const nlohmann::json::exception&) {
        out.notes.push_back("a line of " + log_path.string() + " is not JSON; left out");
      }
    }
  } else {
    out.notes.push_back("no " + log_path.filename().string() +
                        ": robot and ErrP events are not in the events table");
  }
  const LogClock clock(recording, log);
  for (const nlohmann::json& entry : log) {
    const std::string type = logType(entry.value("event", ""));
    if (type.empty() || !entry.contains("t")) continue;
    if (!clock.usable()) {
      out.notes.push_back(
          "the log's phase changes do not match the recording's: robot and ErrP events are not "
          "in the events table");
      break;
    }
    BidsEvent e;
    e.onset_s = std::max(0.0, clock.recordingTime(entry["t"].get<double>()));
    e.sample = std::llround(e.onset_s * rate);
    e.trial_type = type;
    e.value = e.stimulus = e.target = "n/a";
    e.description = describeLogEvent(entry);
    out.rows.push_back(e);
  }
  std::stable_sort(out.rows.begin(), out.rows.end(),
                   [](const BidsEvent& a, const BidsEvent& b) { return a.sample < b.sample; });
  return out;
}

std::string eventsSidecar() {
  nlohmann::ordered_json j;
  j["onset"] = {{"Description", "Seconds from the recording's first sample."}, {"Units", "s"}};
  j["duration"] = {{"Description", "Seconds; a flash's measured duration, 0 for instants."},
                   {"Units", "s"}};
  j["trial_type"] = {
      {"Description",
       "What happened, as kind/condition: epoch by a condition (flash/target) or by a kind "
       "(flash, every flash; MNE selects the kind's conditions by its name)."},
      {"Levels",
       {{"flash/target",
         "a stimulus flash (P300 paradigm) of the attended stimulus: an object, a grid row or a "
         "grid column"},
        {"flash/nontarget", "a stimulus flash of a stimulus not attended"},
        {"flash/unlabelled",
         "a stimulus flash where nobody knows which stimulus was attended (a free choice, or the "
         "intended object out of view): left out of training"},
        {"phase", "the session entered a phase (calibration, objects flashing, ...)"},
        {"selection", "the classifier selected an object or a cell"},
        {"feedback/correct", "the selection shown to the subject was the intended one"},
        {"feedback/error", "the selection shown to the subject was not the intended one"},
        {"feedback/unknown", "a selection shown to the subject, intention unknown"},
        {"errp/accepted", "the error-potential classifier accepted the selection shown"},
        {"errp/rejected", "the error-potential classifier rejected the selection shown"},
        {"errp/decision", "the error-potential classifier's scores for a verdict (from the log)"},
        {"errp/correction", "what followed a rejection: runner-up, repeat, skip or return"},
        {"tracking", "an object's marker was lost or regained by the cameras"},
        {"session", "the session ended, with the reason"},
        {"robot/command", "a command sent to the robot"},
        {"robot/reply", "the robot's reply or a link event"},
        {"placement", "where the robot put the object, against the cell's centre"},
        {"data_loss", "EEG samples lost (zeros in the recording for the duration)"},
        {"amplifier_marker", "a marker the amplifier recorded (a trigger input), type/description"},
        {"padding",
         "zeros after the signal's end that complete the BDF's last record (not signal)"},
        {"annotation", "another note of the recording"}}}};
  j["value"] = {{"Description",
                 "A flash's stimulus code (1-99 objects, 100 + code grid rows and "
                 "columns), n/a otherwise."}};
  j["sample"] = {{"Description", "The recording's sample (from 0) at the onset."}};
  j["stimulus"] = {{"Description",
                    "What a flash's code stood for then (the recording's "
                    "StimulusCodeMap): \"object 10\", \"row 1\", \"column 2\"."}};
  j["target"] = {{"Description", "Whether the subject attended the flashed stimulus."},
                 {"Levels",
                  {{"T", "attended (the cued or intended one)"},
                   {"N", "not attended"},
                   {"U", "unknown: the intended object was not in view"},
                   {"n/a", "not a flash"}}}};
  j["description"] = {{"Description", "The event in words, as the session recorded it."}};
  return j.dump(2) + "\n";
}

}  // namespace arbci::app
