#include "support/robot_test_support.h"

namespace arbci::robot {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

Key testKey() {
  Key key{};
  for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(i * 31 + 5);
  return key;
}

RobotConfig twoObjects() {
  RobotConfig c;
  c.objects = {{1, {0.10, 0.60, 0.06}, 0.06, 0.03}, {2, {-0.15, 0.55, 0.06}, 0.06, 0.03}};
  return c;
}

namespace {
BackendOptions testOptions(double speed, int port, bool stepped) {
  BackendOptions options;
  options.port = port;
  options.stepped = stepped;
  options.speed_factor = speed;
  options.status_interval_s = 0.05;
  return options;
}
}  // namespace

RunningBackend::RunningBackend(double speed, int port, RobotConfig config, bool stepped)
    : RunningBackend(std::make_unique<SimulatedArm>(config), testOptions(speed, port, stepped)) {}

RunningBackend::RunningBackend(std::unique_ptr<RobotDriver> driver, const BackendOptions& options,
                               const Key& key)
    : backend_(std::make_unique<RobotBackend>(key, std::move(driver), options)) {
  thread_ = std::thread([this] { backend_->run(stop_); });
}

void RunningBackend::halt() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool backendReceived(const RunningBackend& backend, std::uint64_t count) {
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (backend.stats().datagrams < count) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

bool waitUntilAccepted(RobotClient& client, std::uint64_t sequence) {
  const auto end = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < end) {
    client.poll();
    for (const RobotEvent& e : client.takeEvents()) {
      if (e.kind == RobotEvent::Kind::Accepted && e.sequence == sequence) return true;
    }
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

ClientOptions fastClient() {
  ClientOptions o;
  o.first_retransmit_s = 0.01;
  o.max_retransmit_s = 0.05;
  o.status_interval_s = 0.02;
  return o;
}

std::vector<RobotEvent> waitFor(RobotClient& client, std::uint64_t sequence,
                                std::chrono::milliseconds timeout) {
  std::vector<RobotEvent> seen;
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    client.poll();
    for (RobotEvent& e : client.takeEvents()) {
      const bool final = e.sequence == sequence && (e.kind == RobotEvent::Kind::Finished ||
                                                    e.kind == RobotEvent::Kind::Rejected ||
                                                    e.kind == RobotEvent::Kind::Failed);
      seen.push_back(std::move(e));
      if (final) return seen;
    }
    std::this_thread::sleep_for(1ms);
  }
  return seen;
}

const RobotEvent& finalEvent(const std::vector<RobotEvent>& events) {
  static const RobotEvent none = [] {
    RobotEvent e{};
    e.kind = RobotEvent::Kind::Failed;
    e.text = "(no event came before the wait ended)";
    return e;
  }();
  return events.empty() ? none : events.back();
}

StatusPayload freshStatus(RobotClient& client) {
  const auto end = Clock::now() + 3s;
  client.takeEvents();
  const auto before = client.status();
  while (Clock::now() < end) {
    client.poll();
    if (client.status() &&
        (!before || client.status()->tool.x != before->tool.x || Clock::now() > end - 2900ms))
      break;
    std::this_thread::sleep_for(1ms);
  }
  // Let two more status replies arrive so the one returned is current.
  const auto settle = Clock::now() + 60ms;
  while (Clock::now() < settle) {
    client.poll();
    std::this_thread::sleep_for(1ms);
  }
  return client.status().value_or(StatusPayload{});
}

std::vector<RobotEvent> pollFor(RobotClient& client, std::chrono::milliseconds duration) {
  std::vector<RobotEvent> seen;
  const auto end = Clock::now() + duration;
  while (Clock::now() < end) {
    client.poll();
    for (RobotEvent& e : client.takeEvents()) seen.push_back(std::move(e));
    std::this_thread::sleep_for(1ms);
  }
  return seen;
}

}  // namespace arbci::robot
