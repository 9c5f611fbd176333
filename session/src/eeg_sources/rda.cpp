// BrainVision Recorder's Remote Data Access (RDA): the TCP stream BrainAmp and actiCHamp labs
// read their amplifiers from (Recorder, or BrainProducts' RDA servers), in its 32-bit form
// (port 51244). Every message starts with a 24-byte header: the RDA GUID (16 bytes), the
// message's whole size and its type (uint32 each, little-endian). A start message (type 1) gives
// the channel count (uint32), the sampling interval in microseconds (double), each channel's
// resolution in microvolts per unit (double) and the channel names (zero-terminated); a data
// message (type 4; type 2 on the 16-bit port) gives its block number, points and marker count
// (uint32 each), the samples multiplexed as float (point by point, every channel), then the
// markers (each: its size, position in the block, points, channel (uint32, uint32, uint32,
// int32), then its type and description, zero-terminated); a stop message (type 3) ends the
// stream (Recorder stopped, or switched to impedance mode).
//
// Blocks carry no time stamps: they are stamped on arrival. Nothing is filled in here: a jump in
// the block number (blocks the server sent and this client never got) and the time a stopped or
// lost stream was away are gaps in the sample numbers, which the acquisition fills with zeros,
// counts and annotates like any source's. The time away is counted from the block numbers where
// they go on after the stop (exact), from the host clock where they start again. A stop, or a
// connection that closes, is a fault while it lasts: the client waits for a new start message
// (reconnecting every second if the connection went) and goes on when data returns, as an LSL
// source does; data that comes after a stop without a start is left out, a fault and a note in
// the recording, since nothing confirms its channels. Markers become annotations
// "<type>/<description>" ("Stimulus/S  1", as BrainVision's marker files name them) on their
// sample.
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include "arbci/core/schema.h"
#include "arbci/session/eeg_sources.h"

namespace arbci::session {
namespace {

struct RdaSettings {
  RdaSettings();
  std::string host;
  int port;
  double connect_timeout_s;
};

const core::Schema<RdaSettings>& rdaSchema() {
  static const core::Schema<RdaSettings> table = [] {
    core::Schema<RdaSettings> t("rda", "BrainVision Recorder's RDA stream (eeg.source \"rda\")");
    t.text("host", &RdaSettings::host, "127.0.0.1", "the computer running Recorder's RDA server")
        .integer("port", &RdaSettings::port, 51244, 1, 65535,
                 "its port: 51244, the 32-bit one (the 16-bit port, 51234, is refused)")
        .number("connect_timeout_s", &RdaSettings::connect_timeout_s, 5.0, 0.1, 600.0,
                "how long to wait for the server and its start message", "s");
    return t;
  }();
  return table;
}

RdaSettings::RdaSettings() {
  rdaSchema().applyDefaults(*this);
}

constexpr std::uint8_t kGuid[16] = {0x8e, 0x45, 0x58, 0x43, 0x96, 0xc9, 0x86, 0x4c,
                                    0xaf, 0x4a, 0x98, 0xbb, 0xf6, 0xc9, 0x14, 0x50};
constexpr std::uint32_t kStart = 1, kData16 = 2, kStop = 3, kData32 = 4;
constexpr std::uint32_t kMaxMessage = 64u << 20;  // a message beyond this is not RDA

std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
template <class T>
T little(const std::uint8_t* p) {  // x86 and ARM hosts are little-endian, as RDA is
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

class RdaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a start message declares; a restart must declare the same.
struct Layout {
  double rate_hz = 0.0;
  std::vector<std::string> channels;
  std::vector<double> resolution;  // microvolts per unit, by channel
  bool operator==(const Layout&) const = default;
};

class RdaSource final : public bci::EegSource {
 public:
  RdaSource(const RdaSettings& settings, int block_size, double expected_rate_hz)
      : settings_(settings), where_(settings.host + ":" + std::to_string(settings.port)) {
    connect();
    const double deadline = bci::hostSeconds() + settings_.connect_timeout_s;
    std::vector<std::uint8_t> message;
    std::uint32_t type = 0;
    while (type != kStart) {
      if (!receive(message, type, deadline))
        throw RdaError("no start message from the RDA server at " + where_ + " in " +
                       core::formatNumber(settings_.connect_timeout_s) + " s" +
                       (closed_ ? " (it closed the connection)" : ""));
      if (type == kData16) throw RdaError(sixteenBit());
    }
    layout_ = readStart(message);
    info_.rate_hz = layout_.rate_hz;
    info_.channels = layout_.channels;
    info_.block_size = block_size;
    if (expected_rate_hz > 0.0 &&
        std::abs(info_.rate_hz - expected_rate_hz) > 1e-6 * expected_rate_hz)
      throw RdaError("the RDA stream at " + where_ + " runs at " +
                     core::formatNumber(info_.rate_hz) + " Hz, the session at " +
                     core::formatNumber(expected_rate_hz) + " Hz (eeg.rate_hz)");
    // The 16-bit port sends the same start message: its first data message says which it is.
    while (receive(message, type, deadline)) {
      if (type == kData16) throw RdaError(sixteenBit());
      if (type == kData32) {
        readData(message);
        break;
      }
    }
    reader_ = std::thread([this] { readLoop(); });
  }
  ~RdaSource() override {
    stop_ = true;
    if (reader_.joinable()) reader_.join();
    if (fd_ >= 0) ::close(fd_);
  }

  const bci::SignalInfo& info() const override { return info_; }

  std::vector<bci::Block> poll(int max_blocks) override {
    std::lock_guard lock(mutex_);
    std::vector<bci::Block> out;
    while (static_cast<int>(out.size()) < max_blocks && !ready_.empty()) {
      out.push_back(std::move(ready_.front()));
      ready_.pop_front();
    }
    const int size = info_.block_size;
    while (static_cast<int>(out.size()) < max_blocks && pendingPoints() >= size)
      out.push_back(takePending(size));
    return out;
  }
  std::vector<bci::Annotation> takeAnnotations() override {
    std::lock_guard lock(mutex_);
    return std::exchange(markers_, {});
  }
  std::string fault() const override {
    std::lock_guard lock(mutex_);
    return fault_;
  }
  std::string describe() const override {
    std::lock_guard lock(mutex_);
    return "RDA stream at " + where_ + ": " + std::to_string(info_.channelCount()) +
           " channels at " + core::formatNumber(info_.rate_hz) + " Hz; " +
           std::to_string(lost_blocks_) + " block(s) lost, " + std::to_string(restarts_) +
           " restart(s), " + std::to_string(gap_samples_) + " samples lost to gaps (" +
           std::to_string(gaps_by_blocks_) + " resumption(s) counted from the block numbers, " +
           std::to_string(gaps_by_clock_) + " from the host clock); " +
           std::to_string(unconfirmed_blocks_) + " block(s) after a stop without a start left out";
  }

 private:
  std::string sixteenBit() const {
    return "the RDA server at " + where_ +
           " sends 16-bit data (Recorder's port 51234): set eeg.rda.port to its 32-bit port, 51244";
  }

  void connect() {
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    if (::getaddrinfo(settings_.host.c_str(), std::to_string(settings_.port).c_str(), &hints,
                      &found) != 0 ||
        !found)
      throw RdaError("cannot resolve the RDA host " + settings_.host);
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int result = fd_ < 0 ? -1 : ::connect(fd_, found->ai_addr, found->ai_addrlen);
    const int error = errno;
    ::freeaddrinfo(found);
    if (result != 0) {
      if (fd_ >= 0) ::close(fd_);
      fd_ = -1;
      throw RdaError("cannot connect to the RDA server at " + where_ + ": " + std::strerror(error) +
                     " (is Recorder's RDA enabled?)");
    }
    closed_ = false;
  }

  // Reads `count` bytes before `deadline` (host seconds); false on a timeout or a closed socket.
  bool readBytes(std::uint8_t* into, size_t count, double deadline) {
    size_t done = 0;
    while (done < count) {
      const double left = deadline - bci::hostSeconds();
      if (left <= 0.0 || stop_) return false;
      pollfd p{fd_, POLLIN, 0};
      const int ready = ::poll(&p, 1, static_cast<int>(std::min(left, 0.1) * 1000.0) + 1);
      if (ready <= 0) continue;
      const ssize_t n = ::recv(fd_, into + done, count - done, 0);
      if (n <= 0) {
        closed_ = true;
        return false;
      }
      done += static_cast<size_t>(n);
    }
    return true;
  }

  // The next whole message (its body after the header); false when none came by `deadline`.
  bool receive(std::vector<std::uint8_t>& body, std::uint32_t& type, double deadline) {
    std::uint8_t header[24];
    if (!readBytes(header, sizeof header, deadline)) return false;
    if (std::memcmp(header, kGuid, sizeof kGuid) != 0)
      throw RdaError("the server at " + where_ + " does not speak RDA (no RDA GUID)");
    const std::uint32_t size = u32(header + 16);
    type = u32(header + 20);
    if (size < 24 || size > kMaxMessage)
      throw RdaError("an RDA message of " + std::to_string(size) + " bytes from " + where_);
    body.resize(size - 24);
    // A message's body follows its header: a partial one is a broken stream, not a slow one.
    return readBytes(body.data(), body.size(), bci::hostSeconds() + 5.0);
  }

  Layout readStart(const std::vector<std::uint8_t>& m) const {
    if (m.size() < 12) throw RdaError("a short RDA start message from " + where_);
    const std::uint32_t channels = u32(m.data());
    const double interval_us = little<double>(m.data() + 4);
    if (channels == 0 || channels > 4096 || m.size() < 12 + 8 * size_t{channels} ||
        !(interval_us > 0.0))
      throw RdaError("an RDA start message with " + std::to_string(channels) +
                     " channels and a sampling interval of " + core::formatNumber(interval_us) +
                     " us from " + where_);
    Layout layout;
    layout.rate_hz = 1e6 / interval_us;
    for (std::uint32_t c = 0; c < channels; ++c)
      layout.resolution.push_back(little<double>(m.data() + 12 + 8 * c));
    size_t at = 12 + 8 * size_t{channels};
    for (std::uint32_t c = 0; c < channels; ++c) {
      std::string name;
      while (at < m.size() && m[at] != 0) name.push_back(static_cast<char>(m[at++]));
      ++at;
      layout.channels.push_back(name.empty() ? "Ch" + std::to_string(c + 1) : name);
    }
    return layout;
  }

  int pendingPoints() const {
    return static_cast<int>(pending_.size() / static_cast<size_t>(info_.channelCount()));
  }
  // The first `points` pending points as a block (channel-major).
  bci::Block takePending(int points) {
    const int channels = info_.channelCount();
    bci::Block block(pending_first_, channels, points);
    for (int s = 0; s < points; ++s)
      for (int c = 0; c < channels; ++c)
        block.at(c, s) = pending_[static_cast<size_t>(s * channels + c)];
    pending_.erase(pending_.begin(),
                   pending_.begin() + static_cast<std::ptrdiff_t>(points) * channels);
    pending_first_ += points;
    return block;
  }
  // `points` samples that never came: what is pending goes out as it is, and the next sample
  // number moves on, so the acquisition sees the gap.
  void skip(std::int64_t points) {
    if (pendingPoints() > 0) ready_.push_back(takePending(pendingPoints()));
    pending_first_ += points;
    gap_samples_ += points;
  }

  void readData(const std::vector<std::uint8_t>& m) {
    const size_t channels = layout_.resolution.size();
    if (m.size() < 12) throw RdaError("a short RDA data message");
    const std::uint32_t block = u32(m.data()), points = u32(m.data() + 4),
                        marker_count = u32(m.data() + 8);
    size_t at = 12 + 4 * size_t{points} * channels;
    if (m.size() < at)
      throw RdaError("an RDA data message shorter than its " + std::to_string(points) + " points");
    const double now = bci::hostSeconds();
    std::lock_guard lock(mutex_);
    if (awaiting_start_) {
      // Data after a stop (or a new connection) with no start message: its layout is not
      // confirmed, so it is not read. The blocks it held become a gap when the stream starts again.
      ++unconfirmed_blocks_;
      if (!unconfirmed_noted_) {
        unconfirmed_noted_ = true;
        fault_ = "the RDA server at " + where_ +
                 " sent data after a stop without a new start message; it is left out until the "
                 "stream starts again";
        markers_.push_back({pending_first_ + pendingPoints(),
                            "RDA: data after a stop without a start message left out", 0});
      }
      return;
    }
    if (resumed_) {
      // After a stop or a lost connection the samples the amplifier took meanwhile are a gap. Where
      // the block numbers go on from the last one they count it exactly; where they start again
      // (or claim more than the time away could hold) the host clock measures it: the time away
      // less this block's own samples.
      resumed_ = false;
      const std::int64_t by_clock =
          std::llround((now - last_data_host_) * info_.rate_hz) - static_cast<std::int64_t>(points);
      const std::uint32_t jump = last_block_ ? block - *last_block_ - 1 : 0x80000000u;
      const std::int64_t by_blocks = static_cast<std::int64_t>(jump) * points;
      if (jump < 0x80000000u &&
          by_blocks <= std::max<std::int64_t>(by_clock, 0) + std::llround(info_.rate_hz)) {
        if (by_blocks > 0) skip(by_blocks);
        ++gaps_by_blocks_;
      } else {
        if (last_data_host_ > 0.0 && by_clock > 0) skip(by_clock);
        ++gaps_by_clock_;
      }
    } else if (last_block_) {
      // Blocks the server sent and this client never got (uint32 arithmetic: the counter wraps).
      const std::uint32_t jump = block - *last_block_ - 1;
      if (jump > 0 && jump < 0x80000000u) {
        skip(static_cast<std::int64_t>(jump) * points);
        lost_blocks_ += jump;
      }
    }
    last_block_ = block;
    last_data_host_ = now;
    const std::int64_t first = pending_first_ + pendingPoints();
    for (size_t i = 0; i < size_t{points} * channels; ++i)
      pending_.push_back(little<float>(m.data() + 12 + 4 * i) *
                         static_cast<float>(layout_.resolution[i % channels]));
    for (std::uint32_t k = 0; k < marker_count && at + 16 <= m.size(); ++k) {
      const std::uint32_t size = u32(m.data() + at), position = u32(m.data() + at + 4),
                          marker_points = u32(m.data() + at + 8);
      if (size < 16 || at + size > m.size()) break;  // a marker cut short: the rest is unusable
      std::string type, description;
      size_t c = at + 16;
      while (c < at + size && m[c] != 0) type.push_back(static_cast<char>(m[c++]));
      ++c;
      while (c < at + size && m[c] != 0) description.push_back(static_cast<char>(m[c++]));
      markers_.push_back({first + position, type + "/" + description,
                          marker_points > 1 ? static_cast<int>(marker_points) : 0});
      at += size;
    }
    if (!fault_.empty()) fault_.clear();
  }

  void setFault(const std::string& text) {
    std::lock_guard lock(mutex_);
    fault_ = text;
  }

  // One attempt to connect again (the read loop then waits for the start message).
  bool reconnect() {
    try {
      connect();
    } catch (const RdaError&) {
      return false;
    }
    return true;
  }

  void readLoop() {
    std::vector<std::uint8_t> message;
    try {
      while (!stop_) {
        if (fd_ < 0 && !reconnect()) {
          for (int i = 0; i < 10 && !stop_; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
          continue;
        }
        std::uint32_t type = 0;
        if (!receive(message, type, bci::hostSeconds() + 0.2)) {
          if (closed_) {
            ::close(fd_);
            fd_ = -1;
            {
              std::lock_guard lock(mutex_);
              resumed_ = true;
              awaiting_start_ = true;
            }
            setFault("the RDA server at " + where_ +
                     " closed the connection; reconnecting when it is back");
          }
          continue;
        }
        if (type == kData32) readData(message);
        if (type == kData16) throw RdaError(sixteenBit());
        if (type == kStop) {
          {
            std::lock_guard lock(mutex_);
            resumed_ = true;
            awaiting_start_ = true;
          }
          setFault("the RDA server at " + where_ +
                   " stopped the stream (Recorder stopped, or switched to impedance mode); "
                   "going on when it starts again");
        }
        if (type == kStart) {
          const Layout layout = readStart(message);
          if (!(layout == layout_))
            throw RdaError("the RDA stream at " + where_ +
                           " started again with other channels or another rate: restart the "
                           "session to take it");
          std::lock_guard lock(mutex_);
          ++restarts_;
          resumed_ = true;
          awaiting_start_ = false;
          unconfirmed_noted_ = false;
        }
      }
    } catch (const std::exception& error) {
      setFault(std::string(error.what()) + " (the stream is not read any further)");
    }
  }

  RdaSettings settings_;
  std::string where_;
  int fd_ = -1;
  bool closed_ = false;
  Layout layout_;
  bci::SignalInfo info_;
  std::thread reader_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::deque<bci::Block> ready_;    // short blocks cut where a gap began
  std::vector<float> pending_;      // multiplexed microvolts not yet in a block
  std::int64_t pending_first_ = 0;  // the sample number of pending_'s first point
  std::vector<bci::Annotation> markers_;
  std::optional<std::uint32_t> last_block_;
  double last_data_host_ = 0.0;
  bool resumed_ = false;            // the next data follows a stop or a reconnection
  bool awaiting_start_ = false;     // stopped or reconnected, and no start message since
  bool unconfirmed_noted_ = false;  // the recording notes data without a start once per stop
  std::int64_t lost_blocks_ = 0, gap_samples_ = 0, unconfirmed_blocks_ = 0;
  int gaps_by_blocks_ = 0, gaps_by_clock_ = 0;  // how each resumption's gap was counted
  int restarts_ = 0;
  std::string fault_;
};

}  // namespace

EegSourceRegistry::Entry rdaEegSource() {
  EegSourceParts parts;
  parts.make = [](const EegSourceContext& c) -> std::unique_ptr<bci::EegSource> {
    RdaSettings rda;
    rdaSchema().read(c.own, rda);
    try {
      return std::make_unique<RdaSource>(rda, c.eeg.block_size, c.eeg.rate_hz);
    } catch (const RdaError& e) {
      throw SessionConfigError(c.session_file + ": eeg.source = \"rda\": " + e.what());
    }
  };
  parts.live = true;
  return {"rda",
          "BrainVision Recorder's Remote Data Access stream (eeg.rda; BrainAmp, actiCHamp), "
          "32-bit, stamped on arrival",
          parts, &rdaSchema()};
}

}  // namespace arbci::session
