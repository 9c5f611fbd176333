#include "arbci/bci/lsl/inlet.h"

#include <netinet/in.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/core/text.h"
#include "lsl/socket.h"

namespace arbci::bci::lsl {
namespace {

constexpr double kConnectTimeoutS = 5.0;
constexpr double kRetryPauseS = 0.25;

void sleepUnless(const std::atomic<bool>& stop, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!stop && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

// The query that finds the same stream again after its outlet restarted (with a new uid).
std::string recoveryQuery(const StreamInfo& s) {
  std::string q = buildQuery(s.session_id, s.name, s.type);
  if (!s.source_id.empty() && s.source_id.find('\'') == std::string::npos)
    q += " and source_id='" + s.source_id + "'";
  else if (!s.hostname.empty() && s.hostname.find('\'') == std::string::npos)
    q += " and hostname='" + s.hostname + "'";
  return q;
}

}  // namespace

Inlet::Inlet(const StreamInfo& stream, LslConfig config, double max_buffer_s, double watchdog_s)
    : info_([&] {
        try {
          return fetchFullInfo(stream, kConnectTimeoutS);
        } catch (const LslError& e) {
          throw LslError("LSL stream \"" + stream.name + "\" on " + stream.hostname + " (" +
                         stream.v4address + ":" + std::to_string(stream.v4data_port) +
                         "): cannot read its description: " + e.what());
        }
      }()),
      config_(std::move(config)),
      codec_(info_.channel_format, info_.channel_count),
      max_samples_(static_cast<std::size_t>(
          std::max(1.0, max_buffer_s * (info_.nominal_srate > 0 ? info_.nominal_srate : 100.0)))),
      watchdog_s_(watchdog_s),
      current_(info_) {
  receive_thread_ = std::thread([this] { receiveLoop(); });
  time_thread_ = std::thread([this] { timeLoop(); });
}

Inlet::~Inlet() {
  stop_ = true;
  if (receive_thread_.joinable()) receive_thread_.join();
  if (time_thread_.joinable()) time_thread_.join();
}

size_t Inlet::pull(std::vector<Sample>& out, size_t max) {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  while (n < max && !queue_.empty()) {
    out.push_back(std::move(queue_.front()));
    queue_.pop_front();
    ++n;
  }
  return n;
}

InletStatus Inlet::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

std::string Inlet::endpoint() const {
  std::lock_guard lock(mutex_);
  return current_.hostname + " (" + current_.v4address + ":" +
         std::to_string(current_.v4data_port) + ")";
}

void Inlet::receiveLoop() {
  bool first = true;
  while (!stop_) {
    if (!first && !findAgain()) {
      sleepUnless(stop_, kRetryPauseS);
      continue;
    }
    first = false;
    try {
      streamOnce();
    } catch (const LslError& e) {
      std::lock_guard lock(mutex_);
      status_.connected = false;
      status_.fault = std::string("lost: ") + e.what();
    }
    if (!stop_) sleepUnless(stop_, kRetryPauseS);
  }
}

bool Inlet::findAgain() {
  StreamInfo previous;
  {
    std::lock_guard lock(mutex_);
    previous = current_;
  }
  std::vector<StreamInfo> found;
  try {
    found = resolveStreams(config_, recoveryQuery(previous), 0.5, 1);
  } catch (const LslError&) {
    return false;
  }
  for (const auto& candidate : found) {
    if (candidate.uid == previous.uid && status().connected) continue;
    if (candidate.channel_count != info_.channel_count ||
        candidate.channel_format != info_.channel_format ||
        candidate.nominal_srate != info_.nominal_srate) {
      std::lock_guard lock(mutex_);
      status_.fault = "the stream came back with another layout (" +
                      std::to_string(candidate.channel_count) + " " +
                      formatName(candidate.channel_format) + " channels at " +
                      std::to_string(candidate.nominal_srate) + " Hz); not taken";
      continue;
    }
    std::lock_guard lock(mutex_);
    current_ = candidate;
    return true;
  }
  return false;
}

void Inlet::streamOnce() {
  StreamInfo target;
  {
    std::lock_guard lock(mutex_);
    target = current_;
  }
  net::TcpStream stream{
      net::tcpConnect(net::endpoint(target.v4address, target.v4data_port), kConnectTimeoutS)};
  stream.setStop(&stop_);
  std::ostringstream request;
  request << "LSL:streamfeed/" << kProtocolVersion << " " << target.uid << "\r\n"
          << "Native-Byte-Order: 1234\r\n"
          << "Endian-Performance: 0\r\n"
          << "Has-IEEE754-Floats: 1\r\n"
          << "Supports-Subnormals: 1\r\n"
          << "Value-Size: " << formatSize(info_.channel_format) << "\r\n"
          << "Data-Protocol-Version: " << kProtocolVersion << "\r\n"
          << "Max-Buffer-Length: " << max_samples_ << "\r\n"
          << "Max-Chunk-Length: 0\r\n"
          << "Hostname: " << target.hostname << "\r\n"
          << "Source-Id: " << target.source_id << "\r\n"
          << "Session-Id: " << target.session_id << "\r\n\r\n";
  stream.writeAll(request.str(), kConnectTimeoutS);

  const std::string status_line = stream.readLine(kConnectTimeoutS);
  std::istringstream status_fields(status_line);
  std::string protocol;
  int code = 0;
  status_fields >> protocol >> code;
  if (protocol.rfind("LSL/", 0) != 0) throw LslError("a malformed reply: \"" + status_line + "\"");
  if (code != 200) throw LslError("the outlet refused: \"" + status_line + "\"");
  bool reverse = false;
  for (std::string line; !(line = stream.readLine(kConnectTimeoutS)).empty();) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = core::lowerCase(core::trimmed(line.substr(0, colon)));
    const std::string value = core::trimmed(line.substr(colon + 1));
    if (key == "byte-order") reverse = value != "1234" && value != "0";
    if (key == "uid" && value != target.uid) throw LslError("the outlet serves another stream now");
    if (key == "data-protocol-version" && value != std::to_string(kProtocolVersion))
      throw LslError("the outlet wants data protocol " + value + "; ARBCI speaks 110");
  }
  const auto read = [&](void* into, size_t bytes) { stream.read(into, bytes, watchdog_s_); };
  for (int pattern : {4, 2}) {
    Sample received;
    codec_.decode(read, reverse, received);
    if (!codec_.same(received, codec_.testPattern(pattern)))
      throw LslError("the test-pattern samples do not match: the formats are incompatible");
  }
  int connection = 0;
  {
    std::lock_guard lock(mutex_);
    status_.connected = true;
    status_.fault.clear();
    connection = ++status_.connections;
  }
  const bool regular = info_.nominal_srate > 0;
  const double period = regular ? 1.0 / info_.nominal_srate : 0.0;
  const double wait = regular ? watchdog_s_ : 3600.0 * 24;
  const auto read_waiting = [&](void* into, size_t bytes) { stream.read(into, bytes, wait); };
  double last = 0.0;
  std::vector<Sample> batch;
  while (!stop_) {
    Sample s;
    s.connection = connection;
    codec_.decode(read_waiting, reverse, s);
    if (s.deduced) s.timestamp = last + period;
    last = s.timestamp;
    batch.push_back(std::move(s));
    // Hand over what has arrived whenever the socket has no more waiting.
    if (stream.buffered() == 0 || batch.size() >= 256) {
      std::lock_guard lock(mutex_);
      for (auto& b : batch) queue_.push_back(std::move(b));
      status_.received += static_cast<std::int64_t>(batch.size());
      batch.clear();
      while (queue_.size() > max_samples_) {
        queue_.pop_front();
        ++status_.overflowed;
      }
    }
  }
}

void Inlet::timeLoop() {
  std::mt19937 random(std::random_device{}());
  while (!stop_) {
    sockaddr_in service{};
    {
      std::lock_guard lock(mutex_);
      try {
        service = net::endpoint(current_.v4address, current_.v4service_port);
      } catch (const LslError&) {
        return;
      }
    }
    try {
      net::Fd socket = net::udpSocket();
      net::bindExact(socket, "0.0.0.0", 0, false);
      const long long wave = random() % 1000000;
      double best_rtt = std::numeric_limits<double>::infinity(), best_offset = 0.0;
      int answers = 0;
      const double end =
          localClock() + config_.time_probe_count * config_.time_probe_interval_s + 0.128;
      double next_probe = localClock();
      int sent = 0;
      while (!stop_ && localClock() < end) {
        if (sent < config_.time_probe_count && localClock() >= next_probe) {
          std::ostringstream probe;
          probe.precision(16);
          probe << "LSL:timedata\r\n" << wave << " " << localClock() << "\r\n";
          net::sendDatagram(socket, probe.str(), service);
          ++sent;
          next_probe += config_.time_probe_interval_s;
        }
        auto reply =
            net::receiveDatagram(socket, std::min(0.02, config_.time_probe_interval_s / 2));
        if (!reply) continue;
        const double t3 = localClock();
        std::istringstream fields(reply->bytes);
        long long id = 0;
        double t0 = 0, t1 = 0, t2 = 0;
        if (!(fields >> id >> t0 >> t1 >> t2) || id != wave) continue;
        const double rtt = (t3 - t0) - (t2 - t1);
        const double remote_minus_local = ((t1 - t0) + (t2 - t3)) / 2.0;
        ++answers;
        if (rtt < best_rtt) {
          best_rtt = rtt;
          best_offset = -remote_minus_local;
        }
      }
      if (answers > 0) {
        std::lock_guard lock(mutex_);
        status_.clock_known = true;
        status_.clock_offset_s = best_offset;
        status_.clock_rtt_s = best_rtt;
      }
    } catch (const LslError&) {
      // No estimate this round; the last one stands.
    }
    sleepUnless(stop_, config_.time_update_interval_s);
  }
}

}  // namespace arbci::bci::lsl
