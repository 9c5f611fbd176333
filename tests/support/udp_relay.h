// A relay between one robot client and a backend on 127.0.0.1, on its own thread, that can do to
// the link what a bad network or an attacker does: lose datagrams each way, cut the link, hold
// commands back and deliver them late, drop chosen replies, and keep copies of what it forwarded
// (to replay them). It decodes with the shared key only to choose; it never forges.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include "arbci/robot/protocol.h"
#include "arbci/robot/udp_socket.h"

namespace arbci::test {

class UdpRelay {
 public:
  using Bytes = std::vector<std::uint8_t>;
  // `real_time`: its thread at the highest priority the process may take (as the link's ends
  // run), so a busy machine delays the client and the backend but not the relay between them.
  UdpRelay(int backend_port, const robot::Key& key, unsigned seed = 1234, bool real_time = false);
  // The longest the relay's own loop went without a turn since the last call (ms): over a few
  // milliseconds, the relay, not the link, held datagrams back.
  double takeLongestStallMs();
  ~UdpRelay();
  UdpRelay(const UdpRelay&) = delete;
  UdpRelay& operator=(const UdpRelay&) = delete;

  int port() const { return front_.port(); }
  void setLoss(double to_backend, double to_client);
  // Everything, both ways, is dropped while cut.
  void setCut(bool cut);
  // Everything forwarded from now on, both ways (or only towards the backend), arrives this much
  // later (a congested or stalled link; one way: an asymmetric path).
  void setDelay(std::chrono::milliseconds delay, bool to_backend_only = false);
  // Commands of this type from the client are held back from now on until release().
  void hold(robot::MessageType command);
  // Sends the held copies of command `sequence` to the backend (in arrival order).
  void release(std::uint64_t sequence);
  void stopHolding();
  // Replies of these types from the backend are dropped.
  void dropReplies(std::set<robot::MessageType> types);
  // Copies of the client's datagrams of this type that reached the relay (held ones included).
  std::vector<Bytes> captured(robot::MessageType command) const;
  // The backend's replies that reached the relay (dropped ones included).
  std::vector<robot::Message> replies() const;
  // Copies of the backend's replies of this type, as sent (to replay them).
  std::vector<Bytes> capturedReplies(robot::MessageType reply) const;
  // Sends `bytes` to the client as if the backend had (a replay from the backend's address).
  void injectReply(const Bytes& bytes);
  std::uint64_t dropped() const { return dropped_; }
  // The send time (the backend's clock, as the client stamped it) of the newest HEARTBEAT passed
  // on to the backend; 0 before any.
  std::int64_t lastHeartbeatForwardedUs() const { return last_heartbeat_us_; }

 private:
  void run();
  void forward(Bytes bytes, bool to_backend);
  bool lose(double probability);

  robot::UdpSocket front_, back_;
  robot::Endpoint backend_;
  robot::Key key_;
  std::mt19937 random_;
  mutable std::mutex mutex_;
  std::atomic<std::int64_t> longest_stall_us_{0};
  double loss_to_backend_ = 0.0, loss_to_client_ = 0.0;
  bool cut_ = false;
  std::chrono::milliseconds delay_{0};
  bool delay_to_backend_only_ = false;
  struct Delayed {
    std::chrono::steady_clock::time_point due;
    Bytes bytes;
    bool to_backend;
  };
  std::vector<Delayed> delayed_;
  std::set<robot::MessageType> holding_, dropping_;
  std::vector<std::pair<std::uint64_t, Bytes>> held_;  // by command sequence
  std::vector<std::pair<robot::MessageType, Bytes>> captured_;
  std::vector<robot::Message> replies_;
  std::vector<std::pair<robot::MessageType, Bytes>> captured_replies_;
  std::optional<robot::Endpoint> client_;
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::int64_t> last_heartbeat_us_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace arbci::test
