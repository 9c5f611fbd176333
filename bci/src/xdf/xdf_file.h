// XDF (the format LabRecorder writes; specification 1.0) parsed by a reader of our own: the
// chunks walked with every length checked against what is left of the file, so a file cut short,
// spliced or with a flipped bit is refused with the byte where it went wrong (or read up to its
// last whole chunk), never read past its end. Private to bci: readXdf() builds the Recording.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace arbci::bci::xdf {

struct Stream {
  std::uint32_t id = 0;
  std::string name, type, source_id, hostname;
  std::string format;  // channel_format: float32, double64, int8..int64 or string
  int channel_count = 0;
  double nominal_rate = 0.0;  // 0: irregular (markers)
  // From desc/channels/channel, as many as the header lists (may be fewer than channel_count).
  std::vector<std::string> labels, units;
  // desc/arbci/parameter elements (name, value): what ARBCI's outlets say of the paradigm.
  std::vector<std::pair<std::string, std::string>> parameters;
  std::vector<double> stamps;                      // one per sample, the stream's own clock
  std::vector<float> values;                       // numeric: sample-major, channel_count each
  std::vector<std::vector<std::string>> strings;   // string streams: each sample's channels
  std::vector<std::pair<double, double>> offsets;  // ClockOffset chunks: (collection time, offset)
  bool footer = false;
  bool numeric() const { return format != "string"; }
  std::size_t samples() const { return stamps.size(); }
};

struct File {
  std::vector<Stream> streams;  // in the order of their headers
  // The file ends inside a chunk: read up to its last whole chunk, which ends at `whole_bytes`.
  bool cut_short = false;
  std::uintmax_t whole_bytes = 0;
};

// Throws RecordingError naming the file and the byte for anything malformed: an unknown chunk
// tag, a length past the file's end that is not at its end, a header that is not XML or declares
// an unusable layout, samples that do not fill their chunk or name an undeclared stream.
File parse(const std::filesystem::path& path);

}  // namespace arbci::bci::xdf
