#include "arbci/bci/recording_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <ctime>
#include <deque>
#include <mutex>
#include <thread>

#include "arbci/bci/recording.h"
#include "bdf_layout.h"

namespace arbci::bci {
namespace {

// The record duration and samples per record: 0.25 s when the rate allows a whole number of
// samples, else the shortest of 0.5, 1, 2, 5 or 10 s that does.
std::pair<double, int> recordLayout(double rate, std::int64_t known_samples) {
  // A known length: the divisor of it nearest 0.25 s whose duration the header's 8 characters
  // hold exactly.
  if (known_samples > 0) {
    std::pair<double, int> best{0.0, 0};
    for (int d = 1; d <= static_cast<int>(10.0 * rate) && d <= known_samples; ++d) {
      if (known_samples % d != 0) continue;
      const double seconds = d / rate;
      if (std::abs(std::stod(bdf::number(seconds, 8)) * rate - d) > 1e-6) continue;
      if (best.second == 0 || std::abs(seconds - 0.25) < std::abs(best.first - 0.25))
        best = {seconds, d};
    }
    if (best.second > 0) return best;
  }
  for (double seconds : {0.25, 0.5, 1.0, 2.0, 5.0, 10.0}) {
    const double samples = rate * seconds;
    if (std::abs(samples - std::round(samples)) < 1e-9 && samples >= 1.0)
      return {seconds, static_cast<int>(std::round(samples))};
  }
  return {1.0, static_cast<int>(std::round(rate))};
}

std::string sanitized(const std::string& text) {
  std::string out;
  for (char c : text) out.push_back(c == '\x14' || c == '\x15' || c == '\0' ? ' ' : c);
  return out;
}

// An open file descriptor, closed on destruction.
class FileHandle {
 public:
  explicit FileHandle(int fd) : fd_(fd) {}
  ~FileHandle() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

struct RecordingWriter::State {
  std::filesystem::path path;
  SignalInfo info;
  RecordingWriterOptions options;
  FileHandle file;
  double record_seconds = 0.25;
  int record_samples = 64;
  int annotation_bytes = bdf::kAnnotationBytes;
  std::int64_t records = 0;
  std::int64_t samples = 0;  // written into records or pending
  std::int64_t clipped = 0;
  std::int64_t shortened = 0;  // annotations cut to fit a record
  std::vector<std::string> shortened_texts;
  std::int64_t padded = 0;
  std::vector<float> pending;  // channel-major, record_samples per channel
  int pending_count = 0;
  std::deque<std::string> annotations;  // TALs waiting for a record
  bool closed = false;

  // Forces the file to the disk once a second.
  std::mutex sync_mutex;
  std::condition_variable sync_wake;
  bool stop_sync = false;
  std::atomic<bool> dirty{false};
  std::thread syncer;

  State(const std::filesystem::path& p, int fd) : path(p), file(fd) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw RecordingError(path.string() + ": " + what);
  }

  void writeAt(const std::string& bytes, off_t offset) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::pwrite(file.get(), bytes.data() + done, bytes.size() - done,
                                 offset + static_cast<off_t>(done));
      if (n < 0) fail(std::string("write failed: ") + std::strerror(errno));
      done += static_cast<size_t>(n);
    }
    dirty = true;
  }

  // An annotation's TAL; text too long for a record's annotation area is cut (and marked).
  std::string tal(double onset, double duration, std::string text) {
    const size_t room = static_cast<size_t>(annotation_bytes) - 64;
    if (text.size() > room) {
      shortened_texts.push_back(text.substr(0, 40));
      text = text.substr(0, room - 16) + " [cut: too long]";
      ++shortened;
    }
    std::string out(1, '+');
    out.append(bdf::seconds(onset));
    if (duration > 0.0) out.append(1, '\x15').append(bdf::seconds(duration));
    out.append(1, '\x14').append(sanitized(text)).append(1, '\x14').append(1, '\0');
    return out;
  }

  void writeRecord() {
    std::string record;
    record.reserve(
        static_cast<size_t>(info.channelCount() * record_samples * 3 + annotation_bytes));
    for (int c = 0; c < info.channelCount(); ++c) {
      for (int s = 0; s < record_samples; ++s) {
        const double value = bdf::digital(pending[static_cast<size_t>(c) * record_samples + s],
                                          -options.range_microvolts, options.range_microvolts);
        const double limited = std::clamp(value, bdf::kDigitalMin, bdf::kDigitalMax);
        if (limited != value || std::isnan(value)) ++clipped;
        bdf::appendInt24(record, std::isnan(value) ? 0 : static_cast<std::int32_t>(limited));
      }
    }
    // The record's time-keeping TAL, then as many waiting annotations as fit.
    std::string annotation_area(1, '+');
    annotation_area.append(bdf::seconds(records * record_seconds))
        .append("\x14\x14")
        .append(1, '\0');
    while (!annotations.empty() && annotation_area.size() + annotations.front().size() <=
                                       static_cast<size_t>(annotation_bytes)) {
      annotation_area += annotations.front();
      annotations.pop_front();
    }
    annotation_area.resize(static_cast<size_t>(annotation_bytes), '\0');
    record += annotation_area;
    const off_t offset = static_cast<off_t>(bdf::headerBytes(info.channelCount() + 1)) +
                         static_cast<off_t>(records) * static_cast<off_t>(record.size());
    writeAt(record, offset);
    ++records;
    writeAt(bdf::field(std::to_string(records), 8), bdf::kRecordCountOffset);
    pending_count = 0;
    std::fill(pending.begin(), pending.end(), 0.0f);
  }

  void syncLoop() {
    std::unique_lock lock(sync_mutex);
    while (!stop_sync) {
      sync_wake.wait_for(lock, std::chrono::seconds(1));
      if (dirty.exchange(false)) ::fdatasync(file.get());
    }
  }
  void stopSyncing() {
    {
      std::lock_guard lock(sync_mutex);
      stop_sync = true;
    }
    sync_wake.notify_all();
    if (syncer.joinable()) syncer.join();
  }
  // Whatever failed (a full disk in the last record), the syncing thread ends with the state: a
  // joinable thread destroyed would terminate the whole session.
  ~State() { stopSyncing(); }
};

RecordingWriter::RecordingWriter(const std::filesystem::path& path, const SignalInfo& info,
                                 const std::map<std::string, std::string>& parameters,
                                 const RecordingWriterOptions& options) {
  if (info.channelCount() == 0)
    throw RecordingError(path.string() + ": a recording needs at least one channel");
  if (!(info.rate_hz > 0.0))
    throw RecordingError(path.string() + ": the sampling rate must be positive");
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw RecordingError(path.string() + ": cannot create: " + std::strerror(errno));
  state_ = std::make_unique<State>(path, fd);
  State& s = *state_;
  s.info = info;
  s.options = options;
  std::tie(s.record_seconds, s.record_samples) = recordLayout(info.rate_hz, options.known_samples);
  s.pending.assign(static_cast<size_t>(info.channelCount()) * s.record_samples, 0.0f);

  bdf::HeaderFields header;
  header.subject = options.subject;
  header.recording_id = options.recording_id;
  header.start = std::time(nullptr);
  header.record_seconds = s.record_seconds;
  for (int c = 0; c < info.channelCount(); ++c) {
    header.signals.push_back({info.channels[c], "uV", -options.range_microvolts,
                              options.range_microvolts, s.record_samples});
  }
  header.annotation_samples = s.annotation_bytes / 3;
  s.writeAt(bdf::header(header), 0);

  for (const auto& [name, value] : parameters)
    s.annotations.push_back(s.tal(0.0, 0.0, "Param " + name + "=" + value));
  s.syncer = std::thread([&s] { s.syncLoop(); });
}

RecordingWriter::~RecordingWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor must not throw; close() explicitly to see the error.
  }
}

void RecordingWriter::write(const Block& block) {
  State& s = *state_;
  if (s.closed) s.fail("write after close");
  if (block.channels != s.info.channelCount()) {
    s.fail("block has " + std::to_string(block.channels) + " channels, the recording " +
           std::to_string(s.info.channelCount()));
  }
  if (block.first_sample != s.samples) {
    s.fail("block starts at sample " + std::to_string(block.first_sample) + ", expected " +
           std::to_string(s.samples));
  }
  for (int i = 0; i < block.samples; ++i) {
    for (int c = 0; c < block.channels; ++c) {
      s.pending[static_cast<size_t>(c) * s.record_samples + s.pending_count] = block.at(c, i);
    }
    ++s.pending_count;
    ++s.samples;
    if (s.pending_count == s.record_samples) s.writeRecord();
  }
}

void RecordingWriter::addStimulus(const StimulusEvent& event) {
  State& s = *state_;
  s.annotations.push_back(s.tal(event.sample / s.info.rate_hz,
                                event.duration_samples / s.info.rate_hz,
                                "Stim " + std::to_string(event.code) +
                                    (!event.known   ? " U"
                                     : event.target ? " T"
                                                    : " N")));
}

void RecordingWriter::addAnnotation(const Annotation& annotation) {
  State& s = *state_;
  s.annotations.push_back(s.tal(annotation.sample / s.info.rate_hz,
                                annotation.duration_samples / s.info.rate_hz, annotation.text));
}

void RecordingWriter::close() {
  if (!state_ || state_->closed) return;
  State& s = *state_;
  s.closed = true;
  const std::int64_t true_samples = s.samples;
  if (s.pending_count > 0 || !s.annotations.empty()) {
    // Padding completes the last record; the marker tells ARBCI's reader where the signal ends.
    const double end = true_samples / s.info.rate_hz;
    const double padded_end = (s.records + 1) * s.record_seconds;
    s.annotations.push_back(
        s.tal(end, padded_end - end, std::string(bdf::kEndMarker) + std::to_string(true_samples)));
    do {
      s.writeRecord();  // throws on a full disk; ~State stops the syncing thread then
    } while (!s.annotations.empty());
    s.padded = s.records * s.record_samples - true_samples;
  }
  s.stopSyncing();
  ::fdatasync(s.file.get());
}

std::int64_t RecordingWriter::samplesWritten() const {
  return state_->samples;
}
std::int64_t RecordingWriter::clippedSamples() const {
  return state_->clipped;
}
std::int64_t RecordingWriter::paddedSamples() const {
  return state_->padded;
}
const std::vector<std::string>& RecordingWriter::shortenedTexts() const {
  return state_->shortened_texts;
}
std::int64_t RecordingWriter::shortenedAnnotations() const {
  return state_->shortened;
}
const std::filesystem::path& RecordingWriter::path() const {
  return state_->path;
}

}  // namespace arbci::bci
