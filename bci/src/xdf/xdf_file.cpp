#include "xdf_file.h"

#include <pugixml.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>

#include "arbci/bci/recording.h"

namespace arbci::bci::xdf {
namespace {

enum Tag : std::uint16_t {
  kFileHeader = 1,
  kStreamHeader = 2,
  kSamples = 3,
  kClockOffset = 4,
  kBoundary = 5,
  kStreamFooter = 6,
};

// Bytes of one value of each numeric channel format; 0 for strings.
int valueBytes(const std::string& format) {
  static const std::map<std::string, int> kSizes{{"float32", 4}, {"double64", 8}, {"int8", 1},
                                                 {"int16", 2},   {"int32", 4},    {"int64", 8},
                                                 {"string", 0}};
  const auto found = kSizes.find(format);
  return found == kSizes.end() ? -1 : found->second;
}

// A chunk's content, read with bounds checks: every read either fits or fails.
class Reader {
 public:
  Reader(const char* data, std::size_t size) : data_(data), size_(size) {}
  std::size_t left() const { return size_ - at_; }
  bool bytes(void* out, std::size_t n) {
    if (n > left()) return false;
    std::memcpy(out, data_ + at_, n);
    at_ += n;
    return true;
  }
  // XDF's variable-length integer: a byte saying 1, 4 or 8, then the value, little-endian.
  bool length(std::uint64_t& value) {
    std::uint8_t width = 0;
    if (!bytes(&width, 1) || (width != 1 && width != 4 && width != 8)) return false;
    value = 0;
    return bytes(&value, width);
  }
  bool skip(std::size_t n) {
    if (n > left()) return false;
    at_ += n;
    return true;
  }
  const char* here() const { return data_ + at_; }

 private:
  const char* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

template <typename T>
float numberAt(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<float>(v);
}

float valueAt(const char* p, int bytes, bool floating) {
  if (floating) return bytes == 4 ? numberAt<float>(p) : numberAt<double>(p);
  switch (bytes) {
    case 1:
      return numberAt<std::int8_t>(p);
    case 2:
      return numberAt<std::int16_t>(p);
    case 4:
      return numberAt<std::int32_t>(p);
    default:
      return numberAt<std::int64_t>(p);
  }
}

class Parser {
 public:
  explicit Parser(const std::filesystem::path& path) : path_(path) {}

  File run() {
    std::ifstream in(path_, std::ios::binary);
    if (!in) throw RecordingError(path_.string() + ": cannot open it");
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(path_, error);
    if (error) throw RecordingError(path_.string() + ": cannot read its size");
    char magic[4] = {};
    if (!in.read(magic, 4) || std::memcmp(magic, "XDF:", 4) != 0)
      throw RecordingError(path_.string() + ": not an XDF file (no XDF: at its start)");
    std::uintmax_t at = 4;
    std::string content;
    while (at < size) {
      chunk_start_ = at;
      std::uint8_t width = 0;
      in.seekg(static_cast<std::streamoff>(at));
      in.read(reinterpret_cast<char*>(&width), 1);
      if (width != 1 && width != 4 && width != 8)
        corrupt("a chunk length of " + std::to_string(width) + " bytes");
      std::uint64_t length = 0;
      if (at + 1 + width > size) return cut(at);
      in.read(reinterpret_cast<char*>(&length), width);
      at += 1 + width;
      if (length < 2)
        corrupt("a chunk of " + std::to_string(length) + " bytes, too short for its tag");
      if (length > size - at) return cut(chunk_start_);
      content.resize(static_cast<std::size_t>(length));
      if (!in.read(content.data(), static_cast<std::streamsize>(length)))
        throw RecordingError(path_.string() + ": read failed at byte " + std::to_string(at));
      at += length;
      chunk(content);
    }
    file_.whole_bytes = at;
    return std::move(file_);
  }

 private:
  [[noreturn]] void corrupt(const std::string& what) const {
    throw RecordingError(path_.string() + ": corrupt at byte " + std::to_string(chunk_start_) +
                         " (" + what + ")");
  }

  File cut(std::uintmax_t whole) {
    file_.cut_short = true;
    file_.whole_bytes = whole;
    return std::move(file_);
  }

  Stream& declared(std::uint32_t id) {
    const auto found = index_.find(id);
    if (found == index_.end())
      corrupt("data for stream " + std::to_string(id) + ", which has no header before it");
    return file_.streams[found->second];
  }

  void chunk(const std::string& content) {
    Reader r(content.data(), content.size());
    std::uint16_t tag = 0;
    r.bytes(&tag, 2);
    if (tag == kFileHeader) {
      pugi::xml_document doc;
      if (!doc.load_buffer(r.here(), r.left())) corrupt("a file header that is not XML");
      return;
    }
    if (tag == kBoundary) return;  // a resynchronisation mark: 16 bytes of UUID, nothing to keep
    if (tag < kFileHeader || tag > kStreamFooter) corrupt("chunk tag " + std::to_string(tag));
    std::uint32_t id = 0;
    if (!r.bytes(&id, 4)) corrupt("a chunk too short for its stream id");
    switch (tag) {
      case kStreamHeader:
        header(id, r);
        break;
      case kSamples:
        samples(declared(id), r);
        break;
      case kClockOffset: {
        double times[2] = {};
        if (r.left() != 16 || !r.bytes(times, 16))
          corrupt("a clock offset of " + std::to_string(r.left()) + " bytes");
        if (!std::isfinite(times[0]) || !std::isfinite(times[1]))
          corrupt("a clock offset that is not a number");
        declared(id).offsets.emplace_back(times[0], times[1]);
        break;
      }
      case kStreamFooter: {
        pugi::xml_document doc;
        if (!doc.load_buffer(r.here(), r.left())) corrupt("a stream footer that is not XML");
        declared(id).footer = true;
        break;
      }
      default:
        break;
    }
  }

  void header(std::uint32_t id, Reader& r) {
    if (index_.count(id)) corrupt("a second header for stream " + std::to_string(id));
    pugi::xml_document doc;
    if (!doc.load_buffer(r.here(), r.left())) corrupt("a stream header that is not XML");
    const pugi::xml_node info = doc.child("info");
    Stream s;
    s.id = id;
    s.name = info.child_value("name");
    s.type = info.child_value("type");
    s.source_id = info.child_value("source_id");
    s.hostname = info.child_value("hostname");
    s.format = info.child_value("channel_format");
    s.channel_count = std::atoi(info.child_value("channel_count"));
    s.nominal_rate = std::atof(info.child_value("nominal_srate"));
    if (valueBytes(s.format) < 0 || s.channel_count <= 0 || s.channel_count > 65536)
      corrupt("stream " + std::to_string(id) + " declares " + std::to_string(s.channel_count) +
              " channels of \"" + s.format + "\"");
    if (!std::isfinite(s.nominal_rate) || s.nominal_rate < 0 || s.nominal_rate > 1e6)
      corrupt("stream " + std::to_string(id) + " declares a rate of " +
              std::string(info.child_value("nominal_srate")));
    const pugi::xml_node desc = info.child("desc");
    for (pugi::xml_node c : desc.child("channels").children("channel")) {
      s.labels.push_back(c.child_value("label"));
      s.units.push_back(c.child_value("unit"));
    }
    for (pugi::xml_node p : desc.child("arbci").children("parameter"))
      s.parameters.emplace_back(p.attribute("name").value(), p.child_value());
    index_[id] = file_.streams.size();
    file_.streams.push_back(std::move(s));
  }

  // A Samples chunk: a count, then each sample: a stamp (8 bytes, or none: deduced from the
  // previous one and the rate), then its values. Everything must fill the chunk exactly.
  void samples(Stream& s, Reader& r) {
    std::uint64_t count = 0;
    if (!r.length(count)) corrupt("a sample count that cannot be read");
    // Each sample takes at least its stamp byte: a count beyond that is a damaged chunk.
    if (count > r.left())
      corrupt("a count of " + std::to_string(count) + " samples in " + std::to_string(r.left()) +
              " bytes");
    const int bytes = valueBytes(s.format);
    const bool floating = s.format == "float32" || s.format == "double64";
    const std::size_t channels = static_cast<std::size_t>(s.channel_count);
    const double step = s.nominal_rate > 0 ? 1.0 / s.nominal_rate : 0.0;
    const auto misfit = [&] {
      corrupt("samples of stream " + std::to_string(s.id) + " that do not fill their chunk");
    };
    for (std::uint64_t k = 0; k < count; ++k) {
      std::uint8_t stamp_bytes = 0;
      if (!r.bytes(&stamp_bytes, 1) || (stamp_bytes != 0 && stamp_bytes != 8)) misfit();
      double stamp = s.stamps.empty() ? 0.0 : s.stamps.back() + step;
      if (stamp_bytes == 8 && (!r.bytes(&stamp, 8) || !std::isfinite(stamp))) misfit();
      if (bytes > 0) {
        const std::size_t n = channels * static_cast<std::size_t>(bytes);
        if (r.left() < n) misfit();
        for (std::size_t c = 0; c < channels; ++c)
          s.values.push_back(valueAt(r.here() + c * bytes, bytes, floating));
        r.skip(n);
      } else {
        std::vector<std::string> texts(channels);
        for (std::size_t c = 0; c < channels; ++c) {
          std::uint64_t length = 0;
          if (!r.length(length) || length > r.left()) misfit();
          texts[c].assign(r.here(), static_cast<std::size_t>(length));
          r.skip(static_cast<std::size_t>(length));
        }
        s.strings.push_back(std::move(texts));
      }
      s.stamps.push_back(stamp);
    }
    if (r.left() != 0) misfit();
  }

  std::filesystem::path path_;
  File file_;
  std::map<std::uint32_t, std::size_t> index_;
  std::uintmax_t chunk_start_ = 0;
};

}  // namespace

File parse(const std::filesystem::path& path) {
  return Parser(path).run();
}

}  // namespace arbci::bci::xdf
