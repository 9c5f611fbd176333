// XDF (LabRecorder's format) through libxdf: the EEG stream as the recording, the string
// streams' markers as its stimuli and annotations.
#include <unistd.h>
#include <xdf.h>

#include <pugixml.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "arbci/bci/recording.h"

namespace arbci::bci {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw RecordingError(path.string() + ": " + what);
}

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double microvoltsPer(const std::string& unit) {
  const std::string u = lower(unit);
  if (u == "v" || u == "volt" || u == "volts") return 1e6;
  if (u == "mv" || u == "millivolt" || u == "millivolts") return 1e3;
  return 1.0;
}

// ARBCI's markers ("flash <code> target|nontarget|unknown"), "<code> [target|nontarget]" or a bare
// code are stimuli; anything else is an annotation.
bool asStimulus(const std::string& text, StimulusEvent& event) {
  std::istringstream words(text);
  std::string first;
  if (!(words >> first)) return false;
  if (first == "flash" && !(words >> first)) return false;
  try {
    size_t used = 0;
    event.code = std::stoi(first, &used);
    if (used != first.size() || event.code <= 0) return false;
  } catch (const std::exception&) {
    return false;
  }
  std::string label;
  words >> label;
  event.known = label == "target" || label == "nontarget";
  event.target = label == "target";
  std::string rest;
  return !(words >> rest);  // nothing more
}

// Silences libxdf's progress printing on stdout while it loads.
class QuietStdout {
 public:
  QuietStdout() : saved_(std::cout.rdbuf(sink_.rdbuf())) {}
  ~QuietStdout() { std::cout.rdbuf(saved_); }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* saved_;
};

// Reads XDF's variable-length integer at `at` in `bytes` (1, 4 or 8 bytes after a width byte).
bool readLength(const std::string& bytes, size_t& at, std::uint64_t& value) {
  if (at >= bytes.size()) return false;
  const auto width = static_cast<std::uint8_t>(bytes[at++]);
  if ((width != 1 && width != 4 && width != 8) || at + width > bytes.size()) return false;
  value = 0;
  std::memcpy(&value, bytes.data() + at, width);
  at += width;
  return true;
}

// Whether a Samples chunk's content (after the stream id) is exactly whole samples of
// `channels` values of `value_bytes` each (0: strings), each with its optional timestamp.
bool samplesFit(const std::string& bytes, int channels, int value_bytes) {
  size_t at = 0;
  std::uint64_t count = 0;
  if (!readLength(bytes, at, count) || count > bytes.size()) return false;
  for (std::uint64_t s = 0; s < count; ++s) {
    if (at >= bytes.size()) return false;
    const auto stamp = static_cast<std::uint8_t>(bytes[at++]);
    if (stamp != 0 && stamp != 8) return false;
    at += stamp;
    if (value_bytes > 0) {
      at += static_cast<size_t>(channels) * value_bytes;
    } else {
      for (int c = 0; c < channels; ++c) {
        std::uint64_t length = 0;
        if (!readLength(bytes, at, length) || length > bytes.size()) return false;
        at += length;
      }
    }
    if (at > bytes.size()) return false;
  }
  return at == bytes.size();
}

// libxdf trusts a file's chunk lengths and sample layouts (a file cut short, or one wrong byte,
// crashes it), so the chunks are walked here first: each must lie inside the file, carry a known
// tag, name a stream declared before it, parse (the XML ones) and hold whole samples (the
// Samples ones). Returns the length of the part made of whole chunks; throws RecordingError for a
// malformed chunk.
std::uintmax_t checkChunks(const std::filesystem::path& path, bool& cut_short) {
  std::ifstream in(path, std::ios::binary);
  const std::uintmax_t size = std::filesystem::file_size(path);
  char magic[4] = {};
  in.read(magic, 4);
  if (std::string(magic, 4) != "XDF:") fail(path, "not an XDF file (no XDF: at its start)");
  struct Layout {
    int channels = 0;
    int value_bytes = 0;  // 0: strings
  };
  std::map<std::uint32_t, Layout> declared;
  static const std::map<std::string, int> kSizes{{"float32", 4}, {"double64", 8}, {"int8", 1},
                                                 {"int16", 2},   {"int32", 4},    {"int64", 8},
                                                 {"string", 0}};
  std::uintmax_t at = 4;
  cut_short = false;
  while (at < size) {
    const std::uintmax_t chunk_start = at;
    const auto corrupt = [&](const std::string& what) {
      fail(path, "corrupt at byte " + std::to_string(chunk_start) + " (" + what + ")");
    };
    std::uint8_t width = 0;
    in.seekg(static_cast<std::streamoff>(at));
    in.read(reinterpret_cast<char*>(&width), 1);
    if (width != 1 && width != 4 && width != 8)
      corrupt("a chunk length of " + std::to_string(width) + " bytes");
    if (at + 1 + width > size) {
      cut_short = true;
      return chunk_start;
    }
    std::uint64_t length = 0;
    in.read(reinterpret_cast<char*>(&length), width);
    at += 1 + width;
    if (length < 2) corrupt("an empty chunk");
    if (length > size - at) {
      cut_short = true;
      return chunk_start;
    }
    std::string content(static_cast<size_t>(length), '\0');
    in.read(content.data(), static_cast<std::streamsize>(content.size()));
    at += length;
    std::uint16_t tag = 0;
    std::memcpy(&tag, content.data(), 2);
    if (tag < 1 || tag > 6) corrupt("chunk tag " + std::to_string(tag));
    if (tag == 1 || tag == 5) {
      pugi::xml_document doc;
      if (tag == 1 && !doc.load_buffer(content.data() + 2, content.size() - 2))
        corrupt("a file header that is not XML");
      continue;
    }
    if (content.size() < 6) corrupt("a chunk too short for its stream id");
    std::uint32_t stream = 0;
    std::memcpy(&stream, content.data() + 2, 4);
    const std::string body = content.substr(6);
    if (tag == 2) {
      pugi::xml_document doc;
      if (!doc.load_buffer(body.data(), body.size())) corrupt("a stream header that is not XML");
      const pugi::xml_node info = doc.child("info");
      const std::string format = info.child_value("channel_format");
      const int channels = std::atoi(info.child_value("channel_count"));
      const auto value_size = kSizes.find(format);
      if (value_size == kSizes.end() || channels <= 0 || channels > 100000)
        corrupt("stream " + std::to_string(stream) + " declares " + std::to_string(channels) +
                " channels of \"" + format + "\"");
      declared[stream] = {channels, value_size->second};
      continue;
    }
    const auto layout = declared.find(stream);
    if (layout == declared.end())
      corrupt("data for stream " + std::to_string(stream) + ", which has no header before it");
    if (tag == 3 && !samplesFit(body, layout->second.channels, layout->second.value_bytes))
      corrupt("samples of stream " + std::to_string(stream) + " that do not fill their chunk");
    if (tag == 4 && body.size() != 16)
      corrupt("a clock offset of " + std::to_string(body.size()) + " bytes");
    if (tag == 6) {
      pugi::xml_document doc;
      if (!doc.load_buffer(body.data(), body.size())) corrupt("a stream footer that is not XML");
    }
  }
  return at;
}

}  // namespace

Recording readXdf(const std::filesystem::path& path, const ReadOptions& options) {
  bool cut_short = false;
  const std::uintmax_t whole = checkChunks(path, cut_short);
  std::filesystem::path readable = path;
  std::filesystem::path salvaged;
  if (cut_short) {
    if (!options.salvage_truncated)
      fail(path, "cut short at byte " + std::to_string(whole) +
                     " (a recording interrupted?); --salvage reads it up to its last whole chunk");
    // libxdf reads files only: the whole chunks go to a temporary copy.
    salvaged = std::filesystem::temp_directory_path() /
               ("arbci-salvage-" + std::to_string(::getpid()) + ".xdf");
    std::ifstream in(path, std::ios::binary);
    std::ofstream out(salvaged, std::ios::binary);
    std::string bytes(static_cast<size_t>(whole), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    readable = salvaged;
  }
  struct Remove {
    std::filesystem::path p;
    ~Remove() {
      std::error_code ignored;
      if (!p.empty()) std::filesystem::remove(p, ignored);
    }
  } remove_salvaged{salvaged};
  Xdf xdf;
  int status = 0;
  try {
    QuietStdout quiet;
    status = xdf.load_xdf(readable.string());
  } catch (const std::exception& e) {
    fail(path, std::string("not a readable XDF file (") + e.what() + ")");
  }
  if (status != 0) fail(path, "not a readable XDF file (libxdf could not load it)");
  // The EEG: the first regular stream of type EEG, else the regular one with most channels.
  int chosen = -1;
  for (size_t i = 0; i < xdf.streams.size(); ++i) {
    const auto& s = xdf.streams[i];
    if (s.info.nominal_srate <= 0 || s.info.channel_format == "string") continue;
    if (lower(s.info.type) == "eeg") {
      chosen = static_cast<int>(i);
      break;
    }
    if (chosen < 0 || s.info.channel_count > xdf.streams[chosen].info.channel_count)
      chosen = static_cast<int>(i);
  }
  if (chosen < 0) fail(path, "has no stream with a regular sampling rate (no EEG to read)");
  const Xdf::Stream& eeg = xdf.streams[static_cast<size_t>(chosen)];
  Recording r;
  r.source = path.string();
  r.format = "XDF";
  r.info.rate_hz = eeg.info.nominal_srate;
  const int channels = eeg.info.channel_count;
  std::vector<double> scale(static_cast<size_t>(channels), 1.0);
  for (int c = 0; c < channels; ++c) {
    std::string label;
    if (c < static_cast<int>(eeg.info.channels.size())) {
      const auto& meta = eeg.info.channels[static_cast<size_t>(c)];
      if (auto l = meta.find("label"); l != meta.end()) label = l->second;
      if (auto u = meta.find("unit"); u != meta.end())
        scale[static_cast<size_t>(c)] = microvoltsPer(u->second);
    }
    r.info.channels.push_back(label.empty() ? "Ch" + std::to_string(c + 1) : label);
  }
  if (static_cast<int>(eeg.time_series.size()) != channels)
    fail(path, "stream \"" + eeg.info.name + "\" holds " + std::to_string(eeg.time_series.size()) +
                   " channels of samples but declares " + std::to_string(channels));
  r.samples = channels > 0 ? static_cast<std::int64_t>(eeg.time_series[0].size()) : 0;
  r.data.resize(static_cast<size_t>(channels) * static_cast<size_t>(r.samples));
  for (int c = 0; c < channels; ++c) {
    const auto& values = eeg.time_series[static_cast<size_t>(c)];
    if (static_cast<std::int64_t>(values.size()) != r.samples)
      fail(path, "stream \"" + eeg.info.name + "\": channels of unequal length");
    for (std::int64_t s = 0; s < r.samples; ++s)
      r.data[static_cast<size_t>(c) * r.samples + s] =
          static_cast<float>(values[static_cast<size_t>(s)] * scale[static_cast<size_t>(c)]);
  }
  r.parameters["XdfStream"] = eeg.info.name;
  if (cut_short) {
    r.truncated = true;
    r.truncation_note =
        "cut short at byte " + std::to_string(whole) + "; read up to its last whole chunk";
  }
  r.parameters["XdfStreamType"] = eeg.info.type;
  // Markers: each at the first EEG sample taken at or after it (as ARBCI stamps a flash).
  const auto& stamps = eeg.time_stamps;
  for (const auto& [event, stream] : xdf.eventMap) {
    const double at = event.second;
    const auto found = std::lower_bound(stamps.begin(), stamps.end(), at - 1e-6);
    if (found == stamps.end()) continue;  // after the EEG ended
    const std::int64_t sample = found - stamps.begin();
    StimulusEvent stimulus;
    stimulus.sample = sample;
    if (asStimulus(event.first, stimulus))
      r.stimuli.push_back(stimulus);
    else
      r.annotations.push_back({sample, event.first, 0});
  }
  std::stable_sort(
      r.stimuli.begin(), r.stimuli.end(),
      [](const StimulusEvent& a, const StimulusEvent& b) { return a.sample < b.sample; });
  std::stable_sort(r.annotations.begin(), r.annotations.end(),
                   [](const Annotation& a, const Annotation& b) { return a.sample < b.sample; });
  return r;
}

}  // namespace arbci::bci
