// BCI2000 .dat files, format 1.0 and 1.1: a text header (first line "HeaderLen= N SourceCh= C
// StatevectorLen= S [DataFormat= int16|int32|float32]", the state vector definition and the
// parameters), then records of C samples and S bytes of packed state bits. Microvolts are
// (raw - SourceChOffset) * SourceChGain. Stimuli are the runs of non-zero StimulusCode: the run's
// first sample is the onset, StimulusType during it marks a target.
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "arbci/bci/recording.h"

namespace arbci::bci {
namespace {

struct StateField {
  std::string name;
  int length = 0;
  int location = 0;  // bit offset into the state vector
};

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw RecordingError(path.string() + ": " + what);
}

std::string urlDecode(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size() &&
        std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(text[i]);
    }
  }
  return out;
}

std::vector<std::string> tokens(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  std::string token;
  while (in >> token) out.push_back(token);
  return out;
}

// "Key= value" pairs of the first line.
std::map<std::string, std::string> firstLineFields(const std::string& line) {
  std::map<std::string, std::string> fields;
  const std::vector<std::string> t = tokens(line);
  for (size_t i = 0; i + 1 < t.size(); i += 2) {
    if (t[i].empty() || t[i].back() != '=') break;
    fields[t[i].substr(0, t[i].size() - 1)] = t[i + 1];
  }
  return fields;
}

int positiveInt(const std::filesystem::path& path, const std::map<std::string, std::string>& fields,
                const std::string& key, int max) {
  const auto found = fields.find(key);
  if (found == fields.end()) fail(path, "first line lacks " + key + "=");
  int value = -1;
  try {
    size_t used = 0;
    value = std::stoi(found->second, &used);
    if (used != found->second.size()) value = -1;
  } catch (const std::exception&) {
  }
  if (value < 0 || value > max) fail(path, key + "= '" + found->second + "' is not a valid count");
  return value;
}

}  // namespace

double bci2000Number(const Recording& recording, const std::string& name, int index) {
  const std::vector<std::string> values = bci2000Values(recording, name);
  if (index >= static_cast<int>(values.size())) {
    throw RecordingError(recording.source + ": parameter " + name + " has no value " +
                         std::to_string(index + 1));
  }
  const std::string& text = values[index];
  char* end = nullptr;
  const double number = std::strtod(text.c_str(), &end);
  if (end == text.c_str())
    throw RecordingError(recording.source + ": parameter " + name + " = '" + text +
                         "' is not a number");
  const std::string unit(end);
  if (unit == "ms") return number / 1000.0;
  if (unit == "s" || unit == "Hz" || unit == "muV" || unit == "uV" || unit.empty()) return number;
  if (unit == "kHz") return number * 1000.0;
  if (unit == "mV") return number * 1000.0;
  throw RecordingError(recording.source + ": parameter " + name + " = '" + text +
                       "' has an unknown unit");
}

std::vector<std::string> bci2000Values(const Recording& recording, const std::string& name) {
  const auto found = recording.parameters.find(name);
  if (found == recording.parameters.end())
    throw RecordingError(recording.source + ": parameter " + name + " is missing");
  // "type value..." where list types start with a count.
  std::vector<std::string> t = tokens(found->second);
  if (t.empty()) throw RecordingError(recording.source + ": parameter " + name + " is empty");
  const std::string type = t[0];
  t.erase(t.begin());
  if (type.find("list") != std::string::npos && !t.empty()) {
    const size_t count = static_cast<size_t>(std::max(0, std::atoi(t[0].c_str())));
    std::vector<std::string> values;
    for (size_t i = 1; i <= count && i < t.size(); ++i) values.push_back(urlDecode(t[i]));
    return values;
  }
  for (std::string& v : t) v = urlDecode(v);
  return t;
}

Recording readBci2000(const std::filesystem::path& path, const ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open");
  std::error_code error;
  const auto file_size = static_cast<std::int64_t>(std::filesystem::file_size(path, error));
  if (error) fail(path, "cannot read its size");
  std::string first;
  std::getline(in, first);
  const auto fields = firstLineFields(first);
  if (!fields.count("HeaderLen"))
    fail(path, "not a BCI2000 file (no HeaderLen= on the first line)");
  const int header_length = positiveInt(path, fields, "HeaderLen", 100 * 1024 * 1024);
  const int channels = positiveInt(path, fields, "SourceCh", 4096);
  const int state_bytes = positiveInt(path, fields, "StatevectorLen", 1024);
  if (channels == 0) fail(path, "SourceCh= 0: no channels");
  if (header_length > file_size) {
    fail(path, "HeaderLen= " + std::to_string(header_length) + " but the file has only " +
                   std::to_string(file_size) + " bytes");
  }
  std::string format = "int16";
  if (fields.count("DataFormat")) format = fields.at("DataFormat");
  int sample_bytes = 2;
  if (format == "int32" || format == "float32") {
    sample_bytes = 4;
  } else if (format != "int16") {
    fail(path, "DataFormat= " + format + " is not int16, int32 or float32");
  }

  // The text header.
  in.seekg(0);
  std::string header(static_cast<size_t>(header_length), '\0');
  in.read(header.data(), header_length);
  Recording recording;
  recording.source = path.string();
  recording.format = "BCI2000";
  std::vector<StateField> states;
  std::istringstream lines(header);
  std::string line, section;
  std::getline(lines, line);  // the first line
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '[') {
      section = line;
      continue;
    }
    if (section.find("State Vector") != std::string::npos) {
      const std::vector<std::string> t = tokens(line);
      if (t.size() < 5)
        fail(path, "state definition '" + line + "' needs name length value byte bit");
      StateField state{t[0], std::atoi(t[1].c_str()),
                       std::atoi(t[3].c_str()) * 8 + std::atoi(t[4].c_str())};
      if (state.length <= 0 || state.length > 32 ||
          state.location + state.length > state_bytes * 8) {
        fail(path, "state " + state.name + " lies outside the " + std::to_string(state_bytes) +
                       "-byte state vector");
      }
      states.push_back(state);
    } else if (section.find("Parameter") != std::string::npos) {
      // "Section DataType Name= values // comment"
      const size_t comment = line.find("//");
      const std::vector<std::string> t = tokens(line.substr(0, comment));
      if (t.size() < 3 || t[2].back() != '=') continue;
      std::string value = t[1];
      for (size_t i = 3; i < t.size(); ++i) value += " " + t[i];
      recording.parameters[t[2].substr(0, t[2].size() - 1)] = value;
    }
  }

  // Signal properties.
  recording.info.rate_hz = bci2000Number(recording, "SamplingRate");
  if (!(recording.info.rate_hz > 0.0 && recording.info.rate_hz < 1e6))
    fail(path, "SamplingRate is not a valid rate");
  recording.info.block_size = recording.parameters.count("SampleBlockSize")
                                  ? static_cast<int>(bci2000Number(recording, "SampleBlockSize"))
                                  : 15;
  std::vector<std::string> names;
  if (recording.parameters.count("ChannelNames")) names = bci2000Values(recording, "ChannelNames");
  for (int c = 0; c < channels; ++c) {
    recording.info.channels.push_back(c < static_cast<int>(names.size()) && !names[c].empty()
                                          ? names[c]
                                          : "Ch" + std::to_string(c + 1));
  }
  std::vector<double> offset(channels, 0.0), gain(channels, 1.0);
  for (int c = 0; c < channels; ++c) {
    if (recording.parameters.count("SourceChOffset"))
      offset[c] = bci2000Number(recording, "SourceChOffset", c);
    if (recording.parameters.count("SourceChGain"))
      gain[c] = bci2000Number(recording, "SourceChGain", c);
  }

  // Records.
  const std::int64_t record_bytes =
      static_cast<std::int64_t>(channels) * sample_bytes + state_bytes;
  const std::int64_t body = file_size - header_length;
  std::int64_t records = body / record_bytes;
  if (body % record_bytes != 0) {
    const std::string note = "the file ends " + std::to_string(body % record_bytes) +
                             " bytes into record " + std::to_string(records + 1) + " (cut short?)";
    if (!options.salvage_truncated) fail(path, note);
    recording.truncated = true;
    recording.truncation_note = note;
  }
  recording.samples = records;
  recording.data.assign(static_cast<size_t>(channels) * records, 0.0f);
  for (const StateField& s : states)
    recording.states[s.name].assign(static_cast<size_t>(records), 0);
  std::vector<std::uint8_t> record(static_cast<size_t>(record_bytes));
  in.seekg(header_length);
  for (std::int64_t n = 0; n < records; ++n) {
    if (!in.read(reinterpret_cast<char*>(record.data()), record_bytes))
      fail(path, "read failed at record " + std::to_string(n + 1));
    for (int c = 0; c < channels; ++c) {
      const std::uint8_t* p = record.data() + static_cast<size_t>(c) * sample_bytes;
      double raw = 0.0;
      if (format == "int16") {
        std::int16_t v;
        std::memcpy(&v, p, 2);
        raw = v;
      } else if (format == "int32") {
        std::int32_t v;
        std::memcpy(&v, p, 4);
        raw = v;
      } else {
        float v;
        std::memcpy(&v, p, 4);
        raw = v;
      }
      recording.data[static_cast<size_t>(c) * records + n] =
          static_cast<float>((raw - offset[c]) * gain[c]);
    }
    const std::uint8_t* bits = record.data() + static_cast<size_t>(channels) * sample_bytes;
    for (const StateField& s : states) {
      std::int32_t value = 0;
      for (int b = 0; b < s.length; ++b) {
        const int at = s.location + b;
        value |= static_cast<std::int32_t>((bits[at / 8] >> (at % 8)) & 1) << b;
      }
      recording.states[s.name][static_cast<size_t>(n)] = value;
    }
  }

  // Stimuli: runs of non-zero StimulusCode.
  if (recording.states.count("StimulusCode")) {
    const auto& code = recording.states["StimulusCode"];
    const std::vector<std::int32_t>* type =
        recording.states.count("StimulusType") ? &recording.states["StimulusType"] : nullptr;
    for (std::int64_t n = 0; n < records; ++n) {
      if (code[n] == 0 || (n > 0 && code[n - 1] == code[n])) continue;
      StimulusEvent event;
      event.sample = n;
      event.code = code[n];
      std::int64_t end = n;
      while (end < records && code[end] == code[n]) {
        if (type && (*type)[end] != 0) event.target = true;
        ++end;
      }
      event.duration_samples = static_cast<int>(end - n);
      recording.stimuli.push_back(event);
    }
  }
  return recording;
}

}  // namespace arbci::bci
