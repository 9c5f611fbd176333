// robot_link_bench: how fast the backend's watchdog halts the arm when the link is cut during a
// grasp (target: 100 ms after the cut), and how often it halts an arm whose link is only lossy
// (the price of a 100 ms watchdog on a bad network). Loopback UDP, the real client and backend,
// a relay that cuts or loses datagrams; the halt time is taken by the driver itself.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "arbci/robot/backend.h"
#include "arbci/robot/client.h"
#include "support/halt_recording_arm.h"
#include "support/udp_relay.h"

namespace {

using namespace arbci;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

robot::Key benchKey() {
  robot::Key key{};
  for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(i * 37 + 11);
  return key;
}

robot::RobotConfig oneObject() {
  robot::RobotConfig c;
  c.objects = {{1, {0.10, 0.60, 0.06}, 0.06, 0.03}};
  return c;
}

// A backend (real time, default watchdog) on its own thread, its arm noting its halt.
struct Rig {
  std::shared_ptr<std::atomic<Clock::rep>> halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  std::unique_ptr<robot::RobotBackend> backend;
  std::atomic<bool> stop{false};
  std::thread thread;
  explicit Rig(double watchdog_s) {
    robot::BackendOptions options;
    options.watchdog_s = watchdog_s;
    backend = std::make_unique<robot::RobotBackend>(
        benchKey(), std::make_unique<test::HaltRecordingArm>(oneObject(), halted_at), options);
    thread = std::thread([this] { backend->run(stop); });
  }
  ~Rig() {
    stop = true;
    thread.join();
  }
};

void pollFor(robot::RobotClient& client, std::chrono::milliseconds duration) {
  const auto end = Clock::now() + duration;
  while (Clock::now() < end) {
    client.poll();
    std::this_thread::sleep_for(1ms);
  }
}

bool accepted(robot::RobotClient& client, std::uint64_t sequence) {
  const auto end = Clock::now() + 5s;
  while (Clock::now() < end) {
    client.poll();
    for (const auto& e : client.takeEvents()) {
      if (e.sequence == sequence && e.kind == robot::RobotEvent::Kind::Accepted) return true;
    }
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "robot_link_bench: watchdog halt latency after a link cut, and false halts on a "
      "lossy link (loopback)"};
  int cuts = 30, lossy_runs = 10;
  app.add_option("--cuts", cuts, "link cuts during a grasp")->capture_default_str();
  app.add_option("--lossy-runs", lossy_runs, "grasps per loss rate")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::mt19937 random(7);
  std::vector<double> latencies;
  int not_halted = 0;
  for (int i = 0; i < cuts; ++i) {
    Rig rig(0.1);
    test::UdpRelay relay(rig.backend->port(), benchKey(), static_cast<unsigned>(i + 1));
    robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()), benchKey());
    const auto grasp = client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06});
    if (!accepted(client, grasp)) {
      std::fprintf(stderr, "cut %d: the grasp was not accepted\n", i);
      return 1;
    }
    // Cut at a random phase of the heartbeat and of the backend's poll.
    pollFor(client, std::chrono::milliseconds(100 + random() % 300));
    const auto cut = Clock::now();
    relay.setCut(true);
    std::this_thread::sleep_for(400ms);
    if (*rig.halted_at == 0) {
      ++not_halted;
      continue;
    }
    latencies.push_back(std::chrono::duration<double, std::milli>(
                            Clock::time_point(Clock::duration(rig.halted_at->load())) - cut)
                            .count());
  }
  std::printf("Watchdog halt after a link cut during a grasp (watchdog 100 ms, heartbeat 50 Hz)\n");
  std::printf(
      "| cuts | halted | median ms | p95 ms | max ms | target |\n|---|---|---|---|---|---|\n");
  if (latencies.empty()) {
    std::printf("| %d | 0 | - | - | - | <= 100 ms |\n", cuts);
    return 1;
  }
  std::printf("| %d | %zu | %.1f | %.1f | %.1f | <= 100 ms |\n\n", cuts, latencies.size(),
              percentile(latencies, 0.5), percentile(latencies, 0.95),
              *std::max_element(latencies.begin(), latencies.end()));

  std::printf("A grasp (about 3 s) through a lossy link: how often the watchdog halts it\n");
  std::printf(
      "| loss each way | grasps | halted by the watchdog | finished |\n|---|---|---|---|\n");
  for (const double loss : {0.1, 0.3, 0.5}) {
    int halted = 0, finished = 0;
    for (int i = 0; i < lossy_runs; ++i) {
      Rig rig(0.1);
      test::UdpRelay relay(rig.backend->port(), benchKey(), static_cast<unsigned>(100 + i));
      relay.setLoss(loss, loss);
      robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()), benchKey());
      const auto grasp = client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06});
      const auto end = Clock::now() + 20s;
      bool done = false;
      while (!done && Clock::now() < end) {
        client.poll();
        for (const auto& e : client.takeEvents()) {
          if (e.sequence != grasp) continue;
          if (e.kind == robot::RobotEvent::Kind::Finished) {
            done = true;
            if (e.outcome == robot::Outcome::Success) ++finished;
          }
          done |= e.kind == robot::RobotEvent::Kind::Rejected ||
                  e.kind == robot::RobotEvent::Kind::Failed;
        }
        std::this_thread::sleep_for(1ms);
      }
      halted += rig.backend->stats().watchdog_halts > 0 ? 1 : 0;
    }
    std::printf("| %.0f %% | %d | %d | %d |\n", loss * 100.0, lossy_runs, halted, finished);
  }
  return not_halted == 0 ? 0 : 1;
}
