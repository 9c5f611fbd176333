// robot_link_bench: how fast the backend's watchdog halts the arm when the link is cut during a
// grasp (target: the watchdog time after the cut), and how often it halts an arm whose link is
// only lossy (the price of the watchdog on a bad network). Loopback UDP, the real client and
// backend, a relay that cuts or loses datagrams; the halt time is taken by the driver itself.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "support/halt_recording_arm.h"
#include "support/robot_test_support.h"
#include "support/udp_relay.h"

namespace {

using namespace arbci;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// A backend (real time, the default watchdog) whose arm notes when it was halted.
struct Rig {
  std::shared_ptr<std::atomic<Clock::rep>> halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  robot::RunningBackend backend{
      std::make_unique<test::HaltRecordingArm>(robot::twoObjects(), halted_at),
      robot::BackendOptions{}};
};

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
    Rig rig;
    test::UdpRelay relay(rig.backend.port(), robot::testKey(), static_cast<unsigned>(i + 1));
    robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()),
                              robot::testKey());
    const auto grasp = client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06});
    if (!robot::waitUntilAccepted(client, grasp)) {
      std::fprintf(stderr, "cut %d: the grasp was not accepted\n", i);
      return 1;
    }
    // Cut at a random phase of the heartbeat and of the backend's poll.
    robot::pollFor(client, std::chrono::milliseconds(100 + random() % 300));
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
  const double watchdog_ms = robot::BackendOptions{}.watchdog_s * 1000.0;
  std::printf("Watchdog halt after a link cut during a grasp (watchdog %.0f ms, heartbeat 50 Hz)\n",
              watchdog_ms);
  std::printf(
      "| cuts | halted | median ms | p95 ms | max ms | target |\n|---|---|---|---|---|---|\n");
  if (latencies.empty()) {
    std::printf("| %d | 0 | - | - | - | <= %.0f ms |\n", cuts, watchdog_ms);
    return 1;
  }
  std::printf("| %d | %zu | %.1f | %.1f | %.1f | <= %.0f ms |\n\n", cuts, latencies.size(),
              percentile(latencies, 0.5), percentile(latencies, 0.95),
              *std::max_element(latencies.begin(), latencies.end()), watchdog_ms);

  std::printf("A grasp (about 3 s) through a lossy link: how often the watchdog halts it\n");
  std::printf(
      "| loss each way | grasps | halted by the watchdog | finished |\n|---|---|---|---|\n");
  for (const double loss : {0.1, 0.3, 0.5}) {
    int halted = 0, finished = 0;
    for (int i = 0; i < lossy_runs; ++i) {
      Rig rig;
      test::UdpRelay relay(rig.backend.port(), robot::testKey(), static_cast<unsigned>(100 + i));
      relay.setLoss(loss, loss);
      robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()),
                                robot::testKey());
      const auto events =
          robot::waitFor(client, client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06}));
      const robot::RobotEvent& last = robot::finalEvent(events);
      if (last.kind == robot::RobotEvent::Kind::Finished && last.outcome == robot::Outcome::Success)
        ++finished;
      halted += rig.backend.stats().watchdog_halts > 0 ? 1 : 0;
    }
    std::printf("| %.0f %% | %d | %d | %d |\n", loss * 100.0, lossy_runs, halted, finished);
  }
  return not_halted == 0 ? 0 : 1;
}
