// GDF, EDF(+) and BDF(+) through BioSig. ARBCI's own annotations ("Stim <code> T|N|U",
// "Param name=value", the end-of-signal marker) become stimuli, parameters and the true length;
// every other event is kept as an annotation with its text.
#include <biosig.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

#include <mutex>

#include "arbci/bci/recording.h"
#include "arbci/bci/units.h"
#include "arbci/core/text.h"
#include "bdf_layout.h"

namespace arbci::bci {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw RecordingError(path.string() + ": " + what);
}

struct HeaderCloser {
  void operator()(HDRTYPE* hdr) const {
    sclose(hdr);
    destructHDR(hdr);
  }
};
using Header = std::unique_ptr<HDRTYPE, HeaderCloser>;

// "Stim 12 T" -> a stimulus; false for any other text.
bool parseStimulus(const std::string& text, StimulusEvent& event) {
  std::istringstream in(text);
  std::string word, kind;
  int code = 0;
  if (!(in >> word >> code >> kind) || word != "Stim" || code <= 0 ||
      (kind != "T" && kind != "N" && kind != "U"))
    return false;
  std::string rest;
  if (in >> rest) return false;
  event.code = code;
  event.target = kind == "T";
  event.known = kind != "U";
  return true;
}

// The expected size of an EDF/BDF file from its header, to name a truncation precisely.
struct EdfSize {
  bool known = false;
  bool no_signals = false;  // the header says 0 signals
  std::int64_t header = 0, record = 0, records = 0;
};

EdfSize edfSize(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(256, '\0');
  EdfSize size;
  if (!in.read(head.data(), 256)) return size;
  const bool bdf = head[0] == '\xff';
  try {
    size.header = std::stoll(head.substr(184, 8));
    size.records = std::stoll(head.substr(236, 8));
    const int signals = std::stoi(head.substr(252, 4));
    size.no_signals = signals == 0;
    if (signals <= 0 || signals > 4096 || size.header != 256LL * (signals + 1)) return size;
    std::string fields(static_cast<size_t>(signals) * 256, '\0');
    if (!in.read(fields.data(), static_cast<std::streamsize>(fields.size()))) return size;
    for (int s = 0; s < signals; ++s)
      size.record += std::stoll(fields.substr(static_cast<size_t>(signals) * 216 + s * 8, 8));
    size.record *= bdf ? 3 : 2;
    size.known = size.record > 0;
  } catch (const std::exception&) {
  }
  return size;
}

// A temporary file removed when it goes out of scope.
class TemporaryFile {
 public:
  explicit TemporaryFile(const std::filesystem::path& like)
      : path_(std::filesystem::temp_directory_path() /
              ("arbci-salvage-" + std::to_string(::getpid()) + "-" + like.filename().string())) {}
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A copy of an EDF/BDF file cut short, holding its complete records and a header that says so.
void writeSalvagedCopy(const std::filesystem::path& from, const std::filesystem::path& to,
                       const EdfSize& size, std::int64_t complete) {
  std::ifstream in(from, std::ios::binary);
  std::ofstream out(to, std::ios::binary | std::ios::trunc);
  std::string bytes(static_cast<size_t>(size.header + complete * size.record), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size())))
    fail(from, "cannot read it to salvage");
  bytes.replace(bdf::kRecordCountOffset, 8, bdf::field(std::to_string(complete), 8));
  if (!out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())))
    fail(to, "cannot write the salvaged copy");
}

// BioSig reports problems by printing to stderr; ARBCI reports them as one-line errors instead,
// so stderr is pointed at /dev/null while BioSig opens a file.
class SilencedStderr {
 public:
  SilencedStderr() : lock_(mutex()) {
    std::fflush(stderr);
    saved_ = ::dup(STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (null >= 0) {
      ::dup2(null, STDERR_FILENO);
      ::close(null);
    }
  }
  ~SilencedStderr() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, STDERR_FILENO);
      ::close(saved_);
    }
  }
  SilencedStderr(const SilencedStderr&) = delete;
  SilencedStderr& operator=(const SilencedStderr&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  int saved_ = -1;
};

}  // namespace

Recording readWithBiosig(const std::filesystem::path& path, const ReadOptions& options) {
  std::error_code error;
  const auto file_size = static_cast<std::int64_t>(std::filesystem::file_size(path, error));
  if (error) fail(path, "cannot open");
  const EdfSize expected = edfSize(path);
  // BioSig answers a header without signals with "memory allocation failed".
  if (expected.no_signals) fail(path, "the EDF/BDF header declares no signal channels");
  std::unique_ptr<TemporaryFile> salvaged;
  std::string truncation_note;
  if (expected.known && expected.records >= 0) {
    const std::int64_t complete =
        std::max<std::int64_t>(0, (file_size - expected.header) / expected.record);
    if (complete < expected.records) {
      truncation_note = "the header promises " + std::to_string(expected.records) +
                        " records but the file holds " + std::to_string(complete) + " (cut short?)";
      if (!options.salvage_truncated) fail(path, truncation_note);
      if (complete == 0) fail(path, truncation_note + "; nothing to salvage");
      salvaged = std::make_unique<TemporaryFile>(path);
      writeSalvagedCopy(path, salvaged->path(), expected, complete);
    }
  }
  const std::filesystem::path readable = salvaged ? salvaged->path() : path;

  Header hdr;
  biosig_data_type* data = nullptr;
  {
    const SilencedStderr quiet;
    hdr.reset(sopen(readable.c_str(), "r", nullptr));
    if (hdr && !serror2(hdr.get())) {
      biosig_reset_flag(hdr.get(), BIOSIG_FLAG_OVERFLOWDETECTION);
      data = biosig_get_data(hdr.get(), 0);  // read while BioSig's warnings are silenced
    }
  }
  if (!hdr) fail(path, "BioSig could not open it");
  if (serror2(hdr.get())) {
    char* message = biosig_get_errormsg(hdr.get());
    std::string text = message ? core::trimmed(message) : "unknown error";
    std::free(message);
    fail(path, "BioSig: " + text);
  }

  Recording recording;
  recording.source = path.string();
  recording.truncated = salvaged != nullptr;
  recording.truncation_note = truncation_note;
  switch (biosig_get_filetype(hdr.get())) {
    case GDF:
      recording.format = "GDF";
      break;
    case EDF:
      recording.format = "EDF";
      break;
    case BDF:
      recording.format = "BDF";
      break;
    default:
      recording.format = "BioSig";
      break;
  }
  const long channels = biosig_get_number_of_channels(hdr.get());
  const double rate = biosig_get_samplerate(hdr.get());
  const auto samples = static_cast<std::int64_t>(biosig_get_number_of_samples(hdr.get()));
  if (channels <= 0) fail(path, "no signal channels");
  if (!(rate > 0.0) || !std::isfinite(rate)) fail(path, "no valid sampling rate");
  recording.info.rate_hz = rate;
  for (long c = 0; c < channels; ++c) {
    CHANNEL_TYPE* channel = biosig_get_channel(hdr.get(), static_cast<int>(c));
    const char* label = channel ? biosig_channel_get_label(channel) : nullptr;
    recording.info.channels.push_back(label && *label ? core::trimmed(label)
                                                      : "Ch" + std::to_string(c + 1));
    if (channel && biosig_get_channel_samplerate(hdr.get(), static_cast<int>(c)) != rate) {
      fail(path, "channel " + recording.info.channels.back() +
                     " has another sampling rate; mixed rates are not supported");
    }
  }

  // Samples, scaled to microvolts whatever the file's unit.
  if (!data && samples > 0) fail(path, "BioSig could not read the samples");
  recording.samples = samples;
  recording.data.resize(static_cast<size_t>(channels) * samples);
  for (long c = 0; c < channels; ++c) {
    CHANNEL_TYPE* channel = biosig_get_channel(hdr.get(), static_cast<int>(c));
    const std::string unit = channel && biosig_channel_get_physdim(channel)
                                 ? core::trimmed(biosig_channel_get_physdim(channel))
                                 : "";
    const double scale = microvoltsPer(unit);
    for (std::int64_t s = 0; s < samples; ++s) {
      recording.data[static_cast<size_t>(c) * samples + s] =
          static_cast<float>(data[static_cast<size_t>(c) * samples + s] * scale);
    }
  }

  // Events.
  const double event_rate = biosig_get_eventtable_samplerate(hdr.get());
  const double to_samples = event_rate > 0.0 ? rate / event_rate : 1.0;
  std::int64_t end_of_signal = samples;
  const size_t events = biosig_get_number_of_events(hdr.get());
  for (size_t n = 0; n < events; ++n) {
    uint16_t type = 0, channel = 0;
    uint32_t position = 0, duration = 0;
    const char* description = nullptr;
    if (biosig_get_nth_event(hdr.get(), n, &type, &position, &channel, &duration, nullptr,
                             &description) != 0)
      continue;
    const auto sample = static_cast<std::int64_t>(std::llround(position * to_samples));
    const auto length = static_cast<int>(std::lround(duration * to_samples));
    const std::string text =
        description ? core::trimmed(description) : "event type " + std::to_string(type);
    StimulusEvent stimulus;
    if (parseStimulus(text, stimulus)) {
      stimulus.sample = sample;
      stimulus.duration_samples = length;
      recording.stimuli.push_back(stimulus);
    } else if (text.rfind("Param ", 0) == 0 && text.find('=') != std::string::npos) {
      const std::string assignment = text.substr(6);
      const size_t equals = assignment.find('=');
      recording.parameters[assignment.substr(0, equals)] = assignment.substr(equals + 1);
    } else if (text.rfind(bdf::kEndMarker, 0) == 0) {
      end_of_signal = std::atoll(text.c_str() + std::strlen(bdf::kEndMarker));
    } else {
      recording.annotations.push_back({sample, text, length});
    }
  }
  if (end_of_signal >= 0 && end_of_signal < samples) {
    // Drop the padding of ARBCI's last record.
    std::vector<float> kept(static_cast<size_t>(channels) * end_of_signal);
    for (long c = 0; c < channels; ++c) {
      std::copy_n(recording.data.begin() + static_cast<std::ptrdiff_t>(c * samples), end_of_signal,
                  kept.begin() + static_cast<std::ptrdiff_t>(c * end_of_signal));
    }
    recording.data = std::move(kept);
    recording.samples = end_of_signal;
  }
  if (recording.format == "BDF" || recording.format == "EDF") {
    std::ifstream in(path, std::ios::binary);
    std::string head(236, '\0');
    if (in.read(head.data(), 236) && head.substr(192, 4) == "EDF+") recording.format += "+";
    if (head.substr(192, 4) == "BDF+") recording.format += "+";
  }
  return recording;
}

Recording readRecording(const std::filesystem::path& path, const ReadOptions& options) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) fail(path, "no such file");
  if (std::filesystem::is_directory(path, error)) fail(path, "is a directory, not a recording");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open (permissions?)");
  std::string head(16, '\0');
  in.read(head.data(), 16);
  head.resize(static_cast<size_t>(in.gcount()));
  if (head.empty()) fail(path, "is empty");
  if (head.rfind("HeaderLen=", 0) == 0 || head.rfind("BCI2000V=", 0) == 0)
    return readBci2000(path, options);
  const bool edf = head.size() >= 8 && head.substr(0, 8) == "0       ";
  const bool bdf = head.size() >= 8 && head.substr(0, 8) == std::string("\xff") + "BIOSEMI";
  const bool gdf = head.rfind("GDF", 0) == 0;
  if (edf || bdf || gdf) return readWithBiosig(path, options);
  if (head.rfind("XDF:", 0) == 0) return readXdf(path, options);
  fail(path, "unknown format (not BCI2000 .dat, GDF, EDF, BDF or XDF)");
}

}  // namespace arbci::bci
