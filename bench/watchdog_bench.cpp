// watchdog_bench: the backend's watchdog at its default (robot.watchdog_ms) against a busy machine
// and against a client that dies. Run it alone and under load (bench/under-load runs both):
//   1. false halts: grasps commanded by a live client whose process runs a frame loop; the
//      watchdog must never halt them (the heartbeat thread must not starve);
//   2. dead clients: a client in a child process is paused (SIGSTOP) or killed (SIGKILL) during a
//      grasp; the arm must be halted within the watchdog time + 100 ms of that instant.
// Loopback UDP, the real client and backend; the halt instant is taken by the arm itself.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "arbci/robot/simulated_arm.h"
#include "support/halt_recording_arm.h"
#include "support/robot_test_support.h"

namespace {

using namespace arbci;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

// The client's side of a dead-client trial, in the child: bind, grasp, say so, then run a frame
// loop until stopped or killed.
[[noreturn]] void childClient(int port, int ready_fd) {
  robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", port), robot::testKey());
  const auto grasp = client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06});
  const bool accepted = robot::waitUntilAccepted(client, grasp);
  const char byte = accepted ? 'a' : 'n';
  if (::write(ready_fd, &byte, 1) != 1) _exit(2);
  for (;;) {
    client.poll();
    std::this_thread::sleep_for(16ms);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"watchdog_bench: false halts of live grasps, halts of dead clients (loopback)"};
  int grasps = 100, dead = 20;
  double speed = 4.0;
  app.add_option("--grasps", grasps, "grasps by a live client")->capture_default_str();
  app.add_option("--dead", dead, "grasps whose client is paused or killed")->capture_default_str();
  app.add_option("--speed", speed, "the simulated arm's speed factor")->capture_default_str();
  double watchdog_ms = robot::BackendOptions{}.watchdog_s * 1000.0;
  app.add_option("--watchdog-ms", watchdog_ms, "the backend's watchdog")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  // 1. Live clients: the motions alternate grasping object 1 and putting it back.
  int false_halts = 0, finished = 0;
  std::string priority;
  {
    robot::BackendOptions options;
    options.speed_factor = speed;
    options.watchdog_s = watchdog_ms / 1000.0;
    options.raise_priority = true;  // as arbci-robotd runs
    robot::RunningBackend backend(std::make_unique<robot::SimulatedArm>(robot::twoObjects()),
                                  options);
    robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                              robot::testKey());
    for (int i = 0; i < grasps; ++i) {
      // Object 1 taken up, then put back where it stood: a motion each.
      const auto type = i % 2 == 0 ? robot::MessageType::Grasp : robot::MessageType::Drop;
      const auto sequence = client.send(type, {0.10, 0.60, 0.06});
      const auto give_up = Clock::now() + 60s;
      std::optional<robot::RobotEvent> end;
      while (!end && Clock::now() < give_up) {
        client.poll();  // a frame loop: poll, then wait for the next frame
        for (const robot::RobotEvent& e : client.takeEvents()) {
          if (e.sequence == sequence && (e.kind == robot::RobotEvent::Kind::Finished ||
                                         e.kind == robot::RobotEvent::Kind::Rejected ||
                                         e.kind == robot::RobotEvent::Kind::Failed))
            end = e;
        }
        std::this_thread::sleep_for(16ms);
      }
      if (end && end->kind == robot::RobotEvent::Kind::Finished &&
          end->outcome == robot::Outcome::Success) {
        ++finished;
      } else if (end && end->text.find("link lost") != std::string::npos) {
        ++false_halts;
        std::fprintf(stderr, "motion %d halted: %s\n", i, end->text.c_str());
        client.send(robot::MessageType::Reset);
      } else {
        std::fprintf(stderr, "motion %d: %s\n", i, end ? end->text.c_str() : "no answer in 60 s");
      }
    }
    priority = client.heartbeatPriority();
  }

  // 2. Dead clients.
  std::mt19937 random(11);
  std::vector<double> latencies;
  int not_halted = 0;
  for (int i = 0; i < dead; ++i) {
    auto halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
    robot::BackendOptions options;
    options.speed_factor = 1.0;  // real time: the grasp takes seconds
    options.watchdog_s = watchdog_ms / 1000.0;
    options.raise_priority = true;
    robot::RunningBackend backend(
        std::make_unique<test::HaltRecordingArm>(robot::twoObjects(), halted_at), options);
    int ready[2];
    if (::pipe(ready) != 0) return 1;
    const pid_t child = ::fork();
    if (child == 0) {
      ::close(ready[0]);
      childClient(backend.port(), ready[1]);
    }
    ::close(ready[1]);
    char byte = 0;
    const bool accepted = ::read(ready[0], &byte, 1) == 1 && byte == 'a';
    ::close(ready[0]);
    if (!accepted) {
      ::kill(child, SIGKILL);
      ::waitpid(child, nullptr, 0);
      std::fprintf(stderr, "dead-client trial %d: the grasp was not accepted\n", i);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + random() % 300));
    const int signal_number = i % 2 == 0 ? SIGSTOP : SIGKILL;
    const auto stopped = Clock::now();
    ::kill(child, signal_number);
    const auto give_up = stopped + 5s;
    while (*halted_at == 0 && Clock::now() < give_up) std::this_thread::sleep_for(1ms);
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    if (*halted_at == 0) {
      ++not_halted;
      continue;
    }
    latencies.push_back(std::chrono::duration<double, std::milli>(
                            Clock::time_point(Clock::duration(halted_at->load())) - stopped)
                            .count());
  }

  // A dead client's last heartbeat left at most one heartbeat period before the signal: the halt
  // is due within the watchdog time of the signal, give or take that period.
  const double period_ms =
      std::max(1000.0 / 200.0, watchdog_ms / robot::ClientOptions{}.heartbeats_per_watchdog);
  const double target_ms = watchdog_ms + period_ms;
  std::printf("Watchdog %.0f ms, a client heartbeat every %.1f ms at %s\n\n", watchdog_ms,
              period_ms, priority.c_str());
  std::printf("| live motions | finished | halted by the watchdog (false) |\n|---|---|---|\n");
  std::printf("| %d | %d | %d |\n\n", grasps, finished, false_halts);
  std::printf(
      "| dead clients (SIGSTOP, SIGKILL) | halted | median ms | p95 ms | max ms | target |\n"
      "|---|---|---|---|---|---|\n");
  if (latencies.empty()) {
    std::printf("| %d | 0 | - | - | - | <= %.0f ms |\n", dead, target_ms);
    return 1;
  }
  const double worst = *std::max_element(latencies.begin(), latencies.end());
  std::printf("| %d | %zu | %.1f | %.1f | %.1f | <= %.0f ms |\n", dead, latencies.size(),
              percentile(latencies, 0.5), percentile(latencies, 0.95), worst, target_ms);
  return false_halts == 0 && not_halted == 0 && worst <= target_ms ? 0 : 1;
}
