// A robot client spoken by hand, byte for byte as the protocol says, to probe the backend's
// edges (tests only).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

#include "arbci/robot/protocol.h"
#include "arbci/robot/udp_socket.h"
#include "support/robot_test_support.h"

namespace arbci::robot {

// Speaks the protocol by hand, byte for byte as a client would, to probe the backend's edges.
class RawSession {
 public:
  explicit RawSession(int backend_port) : backend_(Endpoint::resolve("127.0.0.1", backend_port)) {}
  Message message(MessageType type, std::uint64_t sequence) const {
    Message m;
    m.type = type;
    m.session = kSession;
    m.sequence = sequence;
    m.timestamp_ms = wallClockMs();
    m.boot = type == MessageType::Hello ? 0 : boot_;
    m.stop_epoch = epoch_;
    return m;
  }
  void send(const Message& m) { send(m, socket); }
  void send(const Message& m, UdpSocket& from) { from.sendTo(encode(m, testKey()), backend_); }
  // The next message for this session arriving on `on` within `timeout`.
  std::optional<Message> receive(std::chrono::milliseconds timeout, UdpSocket& on) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      on.wait(2);
      while (auto d = on.receive()) {
        const Decoded decoded = decode(d->bytes.data(), d->bytes.size(), testKey());
        if (decoded.ok() && decoded.message.session == kSession) return decoded.message;
      }
    }
    return std::nullopt;
  }
  std::optional<Message> receive(std::chrono::milliseconds timeout) {
    return receive(timeout, socket);
  }
  // The next reply answering `sequence` (status pushes answer 0).
  std::optional<Message> answer(std::uint64_t sequence,
                                std::chrono::milliseconds timeout = std::chrono::seconds(2)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      const auto m = receive(std::chrono::duration_cast<std::chrono::milliseconds>(
          end - std::chrono::steady_clock::now() + std::chrono::milliseconds(1)));
      if (m && m->sequence == sequence) return m;
    }
    return std::nullopt;
  }
  // The whole handshake: HELLO with a nonce, the WELCOME echoing it, BIND with its challenge
  // (sequence + 1), BOUND.
  bool hello(std::uint64_t sequence) {
    Message hello = message(MessageType::Hello, sequence);
    hello.nonce = 0x1234 + sequence;
    send(hello);
    const auto welcome = answer(sequence);
    if (!welcome || welcome->type != MessageType::Welcome || welcome->nonce != hello.nonce)
      return false;
    boot_ = welcome->boot;
    Message bind = message(MessageType::Bind, sequence + 1);
    bind.challenge = welcome->challenge;
    send(bind);
    const auto bound = answer(sequence + 1);
    if (!bound || bound->type != MessageType::Bound) return false;
    epoch_ = bound->stop_epoch;
    return true;
  }
  // A heartbeat sent `age` ago on the backend's clock (this machine's steady clock).
  void heartbeat(std::uint64_t sequence,
                 std::chrono::microseconds age = std::chrono::microseconds(0)) {
    Message m = message(MessageType::Heartbeat, sequence);
    m.time_us = steadyMicros() - age.count();
    send(m);
  }
  UdpSocket socket;

 private:
  static constexpr std::uint64_t kSession = 4242;
  Endpoint backend_;
  std::uint64_t boot_ = 0, epoch_ = 0;
};

}  // namespace arbci::robot
