#include "arbci/robot/protocol.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

namespace arbci::robot {
namespace {

class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : out_(out) {}
  template <typename T>
  void integer(T value) {
    for (size_t i = 0; i < sizeof(T); ++i)
      out_.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i)));
  }
  void real(double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, 8);
    integer(bits);
  }
  void vec(const Vec3& v) {
    real(v.x);
    real(v.y);
    real(v.z);
  }
  void text(const std::string& s) {
    const size_t n = std::min<size_t>(s.size(), 400);
    integer(static_cast<std::uint16_t>(n));
    out_.insert(out_.end(), s.begin(), s.begin() + static_cast<std::ptrdiff_t>(n));
  }

 private:
  std::vector<std::uint8_t>& out_;
};

// Reads within bounds; any overrun sets `failed` and yields zeros.
class Reader {
 public:
  Reader(const std::uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  T integer() {
    if (at_ + sizeof(T) > size_) {
      failed = true;
      return T{};
    }
    std::uint64_t value = 0;
    for (size_t i = 0; i < sizeof(T); ++i)
      value |= static_cast<std::uint64_t>(data_[at_ + i]) << (8 * i);
    at_ += sizeof(T);
    return static_cast<T>(value);
  }
  double real() {
    const std::uint64_t bits = integer<std::uint64_t>();
    double value;
    std::memcpy(&value, &bits, 8);
    return value;
  }
  Vec3 vec() {
    Vec3 v;
    v.x = real();
    v.y = real();
    v.z = real();
    return v;
  }
  std::string text() {
    const auto n = integer<std::uint16_t>();
    if (failed || at_ + n > size_ || n > 400) {
      failed = true;
      return {};
    }
    std::string s(reinterpret_cast<const char*>(data_ + at_), n);
    at_ += n;
    return s;
  }
  bool done() const { return at_ == size_; }
  bool failed = false;

 private:
  const std::uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

std::array<std::uint8_t, kMacBytes> mac(const std::uint8_t* data, size_t size, const Key& key) {
  std::array<std::uint8_t, kMacBytes> out{};
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), data, size, out.data(), &length);
  return out;
}

bool validType(std::uint8_t t) {
  return (t >= 1 && t <= 9) || (t >= 0x81 && t <= 0x87);
}

// A HELLO is padded to the size of the WELCOME it asks for, so that a HELLO replayed with
// another sender's address cannot make the backend send more bytes than it was sent.
constexpr size_t kHelloPadding = 28;
bool finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void writePayload(Writer& w, const Message& m) {
  switch (m.type) {
    case MessageType::Grasp:
    case MessageType::Drop:
      w.vec(m.target);
      w.integer(m.stop_epoch);
      break;
    case MessageType::Home:
      w.integer(m.stop_epoch);
      break;
    case MessageType::Status:
      if (m.clock_s) w.real(*m.clock_s);
      break;
    case MessageType::Hello:
      w.integer(m.nonce);
      for (size_t i = 0; i < kHelloPadding; ++i) w.integer(std::uint8_t{0});
      break;
    case MessageType::Bind:
      w.integer(m.challenge);
      break;
    case MessageType::Heartbeat:
      w.integer(m.abandon_below);
      w.integer(m.time_us);
      break;
    case MessageType::Welcome:
      w.integer(m.watchdog_ms);
      w.integer(m.nonce);
      w.integer(m.challenge);
      w.integer(m.time_us);
      w.integer(m.stop_epoch);
      break;
    case MessageType::Accepted:
    case MessageType::Bound:
      w.integer(m.stop_epoch);
      break;
    case MessageType::Rejected:
      w.integer(static_cast<std::uint8_t>(m.reason));
      w.text(m.text);
      break;
    case MessageType::Finished:
      w.integer(static_cast<std::uint8_t>(m.outcome));
      w.text(m.text);
      break;
    case MessageType::StatusReply: {
      const StatusPayload& s = m.status;
      w.integer(static_cast<std::uint8_t>(s.state));
      w.vec(s.tool);
      w.real(s.gripper_opening);
      w.integer(s.holding);
      w.integer(static_cast<std::uint8_t>(s.current_command));
      w.integer(s.current_sequence);
      w.integer(static_cast<std::uint8_t>(s.current_is_yours ? 1 : 0));
      w.real(s.progress);
      w.integer(s.last_finished_sequence);
      w.integer(static_cast<std::uint8_t>(s.last_outcome));
      w.text(s.last_outcome_text.substr(0, 200));
      w.text(s.stop_reason.substr(0, 200));
      w.integer(s.stop_epoch);
      w.integer(s.backend_time_us);
      const size_t n = std::min<size_t>(s.objects.size(), kMaxWorldObjects);
      w.integer(static_cast<std::uint8_t>(n));
      for (size_t i = 0; i < n; ++i) {
        w.integer(s.objects[i].id);
        w.vec(s.objects[i].position);
        w.integer(static_cast<std::uint8_t>(s.objects[i].held ? 1 : 0));
        for (double q : s.objects[i].orientation)
          w.integer(static_cast<std::int16_t>(std::lround(std::clamp(q, -1.0, 1.0) * 32767.0)));
      }
      break;
    }
    default:
      break;
  }
}

bool readPayload(Reader& r, Message& m) {
  switch (m.type) {
    case MessageType::Grasp:
    case MessageType::Drop:
      m.target = r.vec();
      m.stop_epoch = r.integer<std::uint64_t>();
      return !r.failed && finite(m.target);
    case MessageType::Home:
      m.stop_epoch = r.integer<std::uint64_t>();
      return !r.failed;
    case MessageType::Hello: {
      m.nonce = r.integer<std::uint64_t>();
      bool zero = true;
      for (size_t i = 0; i < kHelloPadding; ++i) zero &= r.integer<std::uint8_t>() == 0;
      return !r.failed && zero;
    }
    case MessageType::Bind:
      m.challenge = r.integer<std::uint64_t>();
      return !r.failed;
    case MessageType::Accepted:
    case MessageType::Bound:
      m.stop_epoch = r.integer<std::uint64_t>();
      return !r.failed;
    case MessageType::Status:
      // Empty, or the requester's clock for a stepped backend.
      if (r.done()) return true;
      m.clock_s = r.real();
      return !r.failed && std::isfinite(*m.clock_s) && *m.clock_s >= 0.0;
    case MessageType::Heartbeat:
      m.abandon_below = r.integer<std::uint64_t>();
      m.time_us = r.integer<std::int64_t>();
      return !r.failed;
    case MessageType::Welcome:
      m.watchdog_ms = r.integer<std::uint32_t>();
      m.nonce = r.integer<std::uint64_t>();
      m.challenge = r.integer<std::uint64_t>();
      m.time_us = r.integer<std::int64_t>();
      m.stop_epoch = r.integer<std::uint64_t>();
      return !r.failed;
    case MessageType::Rejected: {
      const auto reason = r.integer<std::uint8_t>();
      if (reason < 1 || reason > 11) return false;
      m.reason = static_cast<RejectReason>(reason);
      m.text = r.text();
      return !r.failed;
    }
    case MessageType::Finished: {
      const auto outcome = r.integer<std::uint8_t>();
      if (outcome > 2) return false;
      m.outcome = static_cast<Outcome>(outcome);
      m.text = r.text();
      return !r.failed;
    }
    case MessageType::StatusReply: {
      StatusPayload& s = m.status;
      const auto state = r.integer<std::uint8_t>();
      if (state > 3) return false;
      s.state = static_cast<RobotState>(state);
      s.tool = r.vec();
      s.gripper_opening = r.real();
      s.holding = r.integer<std::int32_t>();
      const auto command = r.integer<std::uint8_t>();
      if (command < 1 || command > 9) return false;
      s.current_command = static_cast<MessageType>(command);
      s.current_sequence = r.integer<std::uint64_t>();
      const auto yours = r.integer<std::uint8_t>();
      if (yours > 1) return false;
      s.current_is_yours = yours == 1;
      s.progress = r.real();
      s.last_finished_sequence = r.integer<std::uint64_t>();
      const auto outcome = r.integer<std::uint8_t>();
      if (outcome > 2) return false;
      s.last_outcome = static_cast<Outcome>(outcome);
      s.last_outcome_text = r.text();
      s.stop_reason = r.text();
      s.stop_epoch = r.integer<std::uint64_t>();
      s.backend_time_us = r.integer<std::int64_t>();
      const auto n = r.integer<std::uint8_t>();
      if (n > kMaxWorldObjects) return false;
      for (int i = 0; i < n && !r.failed; ++i) {
        WorldObject o;
        o.id = r.integer<std::int32_t>();
        o.position = r.vec();
        o.held = r.integer<std::uint8_t>() != 0;
        double norm = 0.0;
        for (double& q : o.orientation) {
          q = r.integer<std::int16_t>() / 32767.0;
          norm += q * q;
        }
        if (norm < 0.25) return false;  // not a rotation
        for (double& q : o.orientation) q /= std::sqrt(norm);
        s.objects.push_back(o);
      }
      return !r.failed && finite(s.tool);
    }
    default:
      return true;  // no payload
  }
}

}  // namespace

std::vector<std::uint8_t> encode(const Message& m, const Key& key) {
  std::vector<std::uint8_t> out;
  out.reserve(256);
  Writer w(out);
  out.insert(out.end(), {'A', 'R', 'B', 'R'});
  w.integer(kProtocolVersion);
  w.integer(static_cast<std::uint8_t>(m.type));
  w.integer(std::uint16_t{0});
  w.integer(m.session);
  w.integer(m.sequence);
  w.integer(m.timestamp_ms);
  w.integer(m.boot);
  w.integer(std::uint16_t{0});  // payload length, set below
  writePayload(w, m);
  const size_t payload = out.size() - kHeaderBytes;
  out[40] = static_cast<std::uint8_t>(payload & 0xff);
  out[41] = static_cast<std::uint8_t>(payload >> 8);
  const auto tag = mac(out.data(), out.size(), key);
  out.insert(out.end(), tag.begin(), tag.end());
  return out;
}

Decoded decode(const std::uint8_t* data, size_t size, const Key& key) {
  Decoded result;
  if (size < kHeaderBytes + kMacBytes) return {DecodeError::TooShort, {}};
  if (size > kMaxDatagram) return {DecodeError::TooLong, {}};
  if (std::memcmp(data, "ARBR", 4) != 0) return {DecodeError::BadMagic, {}};
  if (data[4] != kProtocolVersion) return {DecodeError::BadVersion, {}};
  if (data[6] != 0 || data[7] != 0) return {DecodeError::BadReserved, {}};
  const size_t payload = static_cast<size_t>(data[40]) | (static_cast<size_t>(data[41]) << 8);
  if (kHeaderBytes + payload + kMacBytes != size) return {DecodeError::BadLength, {}};
  const auto expected = mac(data, kHeaderBytes + payload, key);
  if (CRYPTO_memcmp(expected.data(), data + kHeaderBytes + payload, kMacBytes) != 0)
    return {DecodeError::BadMac, {}};
  if (!validType(data[5])) return {DecodeError::BadType, {}};
  Reader r(data, kHeaderBytes + payload);
  r.integer<std::uint32_t>();  // magic
  r.integer<std::uint8_t>();   // version
  Message& m = result.message;
  m.type = static_cast<MessageType>(r.integer<std::uint8_t>());
  r.integer<std::uint16_t>();
  m.session = r.integer<std::uint64_t>();
  m.sequence = r.integer<std::uint64_t>();
  m.timestamp_ms = r.integer<std::uint64_t>();
  m.boot = r.integer<std::uint64_t>();
  r.integer<std::uint16_t>();
  if (!readPayload(r, m) || !r.done()) return {DecodeError::BadPayload, {}};
  return result;
}

std::optional<Peek> peek(const std::uint8_t* data, size_t size) {
  if (size < kHeaderBytes + kMacBytes || size > kMaxDatagram) return std::nullopt;
  if (std::memcmp(data, "ARBR", 4) != 0 || data[4] != kProtocolVersion) return std::nullopt;
  if (data[6] != 0 || data[7] != 0 || !validType(data[5])) return std::nullopt;
  const size_t payload = static_cast<size_t>(data[40]) | (static_cast<size_t>(data[41]) << 8);
  if (kHeaderBytes + payload + kMacBytes != size) return std::nullopt;
  std::uint64_t session = 0;
  for (size_t i = 0; i < 8; ++i) session |= static_cast<std::uint64_t>(data[8 + i]) << (8 * i);
  return Peek{static_cast<MessageType>(data[5]), session};
}

bool isCommand(MessageType type) {
  return static_cast<std::uint8_t>(type) < 0x80;
}

bool isMotion(MessageType type) {
  return type == MessageType::Grasp || type == MessageType::Drop || type == MessageType::Home;
}

const char* toString(MessageType type) {
  switch (type) {
    case MessageType::Grasp:
      return "GRASP";
    case MessageType::Drop:
      return "DROP";
    case MessageType::Home:
      return "HOME";
    case MessageType::Stop:
      return "STOP";
    case MessageType::Status:
      return "STATUS";
    case MessageType::Hello:
      return "HELLO";
    case MessageType::Reset:
      return "RESET";
    case MessageType::Bind:
      return "BIND";
    case MessageType::Heartbeat:
      return "HEARTBEAT";
    case MessageType::Welcome:
      return "WELCOME";
    case MessageType::Bound:
      return "BOUND";
    case MessageType::Accepted:
      return "ACCEPTED";
    case MessageType::Finished:
      return "FINISHED";
    case MessageType::Rejected:
      return "REJECTED";
    case MessageType::StatusReply:
      return "STATUS reply";
    case MessageType::KeyMismatch:
      return "KEY MISMATCH";
  }
  return "unknown";
}

const char* toString(RejectReason reason) {
  switch (reason) {
    case RejectReason::OutsideWorkspace:
      return "outside the workspace";
    case RejectReason::Busy:
      return "busy";
    case RejectReason::Malformed:
      return "malformed";
    case RejectReason::NotAuthenticated:
      return "not authenticated";
    case RejectReason::Replayed:
      return "replayed";
    case RejectReason::Unreachable:
      return "unreachable";
    case RejectReason::InvalidState:
      return "invalid in this state";
    case RejectReason::Stopped:
      return "stopped";
    case RejectReason::UnknownBoot:
      return "another backend run";
    case RejectReason::Cancelled:
      return "cancelled";
    case RejectReason::BeforeStop:
      return "made before a STOP";
  }
  return "unknown";
}

const char* toString(Outcome outcome) {
  switch (outcome) {
    case Outcome::Success:
      return "success";
    case Outcome::Failed:
      return "failed";
    case Outcome::Stopped:
      return "stopped";
  }
  return "unknown";
}

const char* toString(RobotState state) {
  switch (state) {
    case RobotState::Idle:
      return "idle";
    case RobotState::Moving:
      return "moving";
    case RobotState::Stopped:
      return "stopped";
    case RobotState::Fault:
      return "fault";
  }
  return "unknown";
}

const char* toString(DecodeError error) {
  switch (error) {
    case DecodeError::None:
      return "none";
    case DecodeError::TooShort:
      return "too short";
    case DecodeError::TooLong:
      return "too long";
    case DecodeError::BadMagic:
      return "not an ARBCI robot message";
    case DecodeError::BadVersion:
      return "unsupported protocol version";
    case DecodeError::BadReserved:
      return "reserved field not zero";
    case DecodeError::BadLength:
      return "length field does not match";
    case DecodeError::BadMac:
      return "not authenticated (bad MAC)";
    case DecodeError::BadType:
      return "unknown message type";
    case DecodeError::BadPayload:
      return "malformed payload";
  }
  return "unknown";
}

std::int64_t steadyMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::uint64_t wallClockMs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace arbci::robot
