// What the robot tests and the link bench share: a backend on its own thread (real UDP on
// 127.0.0.1), a fast client, and bounded waits for events and statuses.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "arbci/robot/backend.h"
#include "arbci/robot/client.h"
#include "arbci/robot/simulated_arm.h"

namespace arbci::robot {

Key testKey();
RobotConfig twoObjects();

// A backend on its own thread.
class RunningBackend {
 public:
  explicit RunningBackend(double speed, int port = 0, RobotConfig config = twoObjects(),
                          bool stepped = false);
  // With any driver, options and key.
  RunningBackend(std::unique_ptr<RobotDriver> driver, const BackendOptions& options,
                 const Key& key = testKey());
  ~RunningBackend() { halt(); }
  void halt();
  int port() const { return backend_->port(); }
  std::uint64_t boot() const { return backend_->boot(); }
  BackendStats stats() const { return backend_->stats(); }
  const RobotBackend& backend() const { return *backend_; }

 private:
  std::unique_ptr<RobotBackend> backend_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Waits (up to 5 s) until the backend has taken `count` datagrams off its socket.
bool backendReceived(const RunningBackend& backend, std::uint64_t count);
// Polls (up to 5 s) until the backend accepts command `sequence`.
bool waitUntilAccepted(RobotClient& client, std::uint64_t sequence);
ClientOptions fastClient();
// Polls until an event for `sequence` ends it (finished, rejected, failed) or `timeout` passes.
std::vector<RobotEvent> waitFor(RobotClient& client, std::uint64_t sequence,
                                std::chrono::milliseconds timeout = std::chrono::seconds(20));
// The last event seen; when none came before the wait ended, an event that says so (a failed
// wait is a failed assertion, never a null pointer).
const RobotEvent& finalEvent(const std::vector<RobotEvent>& events);
// A status received after this call.
StatusPayload freshStatus(RobotClient& client);
// Polls the client for `duration`, keeping its events.
std::vector<RobotEvent> pollFor(RobotClient& client, std::chrono::milliseconds duration);

}  // namespace arbci::robot
