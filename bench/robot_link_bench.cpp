// robot_link_bench: the robot link against a bad network and a flood, loopback UDP, the real
// client and backend, a relay that cuts, delays or loses datagrams; the halt instant is taken by
// the driver itself.
//   1. a link cut during a grasp: the halt's latency from the cut and from the send time of the
//      last heartbeat that reached the backend (target: within the watchdog time of it);
//   2. a link that starts delaying everything by 1.5 s: the same (a delayed heartbeat is stale);
//   3. a lossy link: how often the watchdog halts a grasp (its price on a bad network);
//   4. a flood of forged datagrams (40,000 a second by default): STOP to ACCEPTED latency and
//      false watchdog halts of live motions, with and without the flood; a STOP from a fresh
//      client (a new address, as `arbci robot stop` from another shell) from its first HELLO;
//   5. fresh clients that send their motion at once, as the CLI does (halts of healthy motions),
//      and a fresh client through a link already known to be slow (refused, never moved).
// `--flood-port P --flood-seconds S` only floods a running arbci-robotd, for timing the real CLI.
// Run it alone and under load (two busy processes, as bench/under-load) for the docs' tables.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "arbci/robot/simulated_arm.h"
#include "support/halt_recording_arm.h"
#include "support/robot_test_support.h"
#include "support/udp_relay.h"

namespace {

using namespace arbci;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double g_watchdog_s = robot::BackendOptions{}.watchdog_s;

std::ostream* g_log = nullptr;  // --log: the backend's lines (halts with their cause)

robot::BackendOptions benchOptions(double speed = 1.0) {
  robot::BackendOptions options;
  options.log = g_log;
  options.speed_factor = speed;
  options.watchdog_s = g_watchdog_s;
  options.raise_priority = true;  // as arbci-robotd runs
  return options;
}

// A backend (real time, the default watchdog) whose arm notes when it was halted.
struct Rig {
  std::shared_ptr<std::atomic<Clock::rep>> halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  robot::RunningBackend backend{
      std::make_unique<test::HaltRecordingArm>(robot::twoObjects(), halted_at), benchOptions()};
  std::int64_t haltedUs() const {
    return std::chrono::duration_cast<std::chrono::microseconds>(Clock::duration(halted_at->load()))
        .count();
  }
};

// The relay going this long without a turn held the link's datagrams itself.
constexpr double kRelayStallMs = 20.0;

// "load 3.1 2.4 1.2 on 2 cores": what the figures were measured under.
std::string loadText() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  double a = 0, b = 0, c = 0;
  if (f) {
    if (std::fscanf(f, "%lf %lf %lf", &a, &b, &c) != 3) a = b = c = 0;
    std::fclose(f);
  }
  char text[96];
  std::snprintf(text, sizeof text, "load %.1f %.1f %.1f on %u cores", a, b, c,
                std::thread::hardware_concurrency());
  return text;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

struct Latencies {
  std::vector<double> from_event, from_heartbeat;
  int not_halted = 0, halted_before = 0;  // the latter: halted before the fault (not counted)
};

// Grasps through the relay; `fault` is applied at a random heartbeat phase; the halt is awaited.
template <typename Fault>
Latencies halts(int runs, unsigned seed, Fault fault) {
  std::mt19937 random(seed);
  Latencies out;
  for (int i = 0; i < runs; ++i) {
    Rig rig;
    test::UdpRelay relay(rig.backend.port(), robot::testKey(), seed + static_cast<unsigned>(i),
                         true);
    robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()),
                              robot::testKey());
    const auto grasp = client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06});
    if (!robot::waitUntilAccepted(client, grasp)) {
      ++out.not_halted;
      continue;
    }
    robot::pollFor(client, std::chrono::milliseconds(100 + random() % 300));
    if (*rig.halted_at != 0) {
      ++out.halted_before;  // a halt of a healthy link is not the fault's
      continue;
    }
    const auto at = Clock::now();
    fault(relay);
    const std::int64_t heartbeat_us = relay.lastHeartbeatForwardedUs();
    std::this_thread::sleep_for(600ms);
    if (*rig.halted_at == 0) {
      ++out.not_halted;
      continue;
    }
    out.from_event.push_back(std::chrono::duration<double, std::milli>(
                                 Clock::time_point(Clock::duration(rig.halted_at->load())) - at)
                                 .count());
    out.from_heartbeat.push_back(static_cast<double>(rig.haltedUs() - heartbeat_us) / 1000.0);
  }
  return out;
}

void printHalts(const char* what, int runs, const Latencies& l) {
  std::printf(
      "| %s | %d | %d | %zu | %.1f / %.1f / %.1f / %.1f | %.1f / %.1f / %.1f / %.1f |\n", what,
      runs, l.halted_before, l.from_event.size(), percentile(l.from_event, 0.5),
      percentile(l.from_event, 0.95), percentile(l.from_event, 0.99),
      l.from_event.empty() ? 0.0 : *std::max_element(l.from_event.begin(), l.from_event.end()),
      percentile(l.from_heartbeat, 0.5), percentile(l.from_heartbeat, 0.95),
      percentile(l.from_heartbeat, 0.99),
      l.from_heartbeat.empty()
          ? 0.0
          : *std::max_element(l.from_heartbeat.begin(), l.from_heartbeat.end()));
}

// Forged datagrams at `rate` a second from another address, in 1 ms bursts: half carry the real
// client's session id in a well-formed header (an attacker who sniffs the LAN), half random ones;
// none has a valid MAC.
class Flood {
 public:
  Flood(int port, std::uint64_t session, double rate) {
    if (rate <= 0.0) return;
    thread_ = std::thread([this, port, session, rate] {
      robot::UdpSocket socket;
      const auto to = robot::Endpoint::resolve("127.0.0.1", port);
      std::mt19937_64 random(5);
      robot::Message m;
      m.type = robot::MessageType::Stop;
      std::vector<std::vector<std::uint8_t>> forged;
      for (int i = 0; i < 64; ++i) {
        m.session = i % 2 ? session : random();
        m.sequence = random();
        m.timestamp_ms = robot::wallClockMs();
        robot::Key wrong{};
        wrong[0] = static_cast<std::uint8_t>(i + 1);
        auto bytes = robot::encode(m, wrong);
        bytes.resize(robot::kMaxDatagram - 40, 0);  // large: the costliest to receive
        bytes[40] = static_cast<std::uint8_t>((bytes.size() - robot::kHeaderBytes - 32) & 0xff);
        bytes[41] = static_cast<std::uint8_t>((bytes.size() - robot::kHeaderBytes - 32) >> 8);
        forged.push_back(std::move(bytes));
      }
      const int per_ms = static_cast<int>(rate / 1000.0);
      auto next = Clock::now();
      size_t k = 0;
      while (!stop_) {
        for (int i = 0; i < per_ms; ++i) {
          socket.sendTo(forged[k++ % forged.size()], to);
          ++sent_;
        }
        next += 1ms;
        std::this_thread::sleep_until(next);
      }
    });
  }
  ~Flood() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  std::uint64_t sent() const { return sent_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> sent_{0};
  std::thread thread_;
};

struct FloodRow {
  std::vector<double> stop_ms;
  int motions = 0, false_halts = 0;
  std::uint64_t sent = 0, shed = 0;
};

FloodRow floodRow(double rate, int stops, int motions) {
  FloodRow row;
  robot::RunningBackend backend(std::make_unique<robot::SimulatedArm>(robot::twoObjects()),
                                benchOptions(8.0));
  robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                            robot::testKey());
  const auto bound_by = Clock::now() + 5s;
  while (!client.connected() && Clock::now() < bound_by) robot::pollFor(client, 5ms);
  // The session id is what a sniffer would see in the header of any of its datagrams.
  Flood flood(backend.port(), client.sessionId(), rate);
  std::this_thread::sleep_for(300ms);  // the flood under way
  for (int i = 0; i < stops; ++i) {
    client.takeEvents();
    const auto sent = Clock::now();
    const auto stop = client.send(robot::MessageType::Stop);
    bool done = false;
    while (!done && Clock::now() - sent < 5s) {
      client.poll();
      for (const auto& e : client.takeEvents()) done |= e.sequence == stop;
      if (!done) std::this_thread::sleep_for(100us);
    }
    row.stop_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
    robot::waitFor(client, client.send(robot::MessageType::Reset), 5s);
    robot::pollFor(client, 20ms);
  }
  const std::uint64_t halts_before = backend.stats().watchdog_halts;
  while (row.motions < motions) {
    // Grasp and put back, in turn: each motion about a second at this speed.
    const bool grasp = row.motions % 2 == 0;
    robot::waitFor(client, grasp ? client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06})
                                 : client.send(robot::MessageType::Drop, {0.10, 0.60, 0.0}));
    ++row.motions;
  }
  row.false_halts = static_cast<int>(backend.stats().watchdog_halts - halts_before);
  row.sent = flood.sent();
  row.shed = backend.stats().shed;
  return row;
}

// STOPs from fresh clients (each a new socket, so a new source address, as `arbci robot stop`
// from another shell) while the session's bound client is there and the flood runs: ms from the
// client's creation (its first HELLO) to the STOP's acceptance.
std::vector<double> freshStops(double rate, int tries) {
  robot::RunningBackend backend(std::make_unique<robot::SimulatedArm>(robot::twoObjects()),
                                benchOptions(8.0));
  robot::RobotClient session(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                             robot::testKey());
  const auto bound_by = Clock::now() + 5s;
  while (!session.connected() && Clock::now() < bound_by) robot::pollFor(session, 5ms);
  Flood flood(backend.port(), session.sessionId(), rate);
  std::this_thread::sleep_for(300ms);
  std::vector<double> ms;
  for (int i = 0; i < tries; ++i) {
    const auto start = Clock::now();
    robot::RobotClient fresh(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                             robot::testKey());
    const auto stop = fresh.send(robot::MessageType::Stop);
    bool accepted = false;
    while (!accepted && Clock::now() - start < 20s) {
      fresh.poll();
      accepted = fresh.accepted(stop);
      if (!accepted) std::this_thread::sleep_for(100us);
    }
    ms.push_back(accepted ? std::chrono::duration<double, std::milli>(Clock::now() - start).count()
                          : 1e9);
    robot::waitFor(session, session.send(robot::MessageType::Reset), 5s);
  }
  return ms;
}

// Fresh clients, each sending its motion at once (as the CLI does) at real speed: how many of
// these healthy motions the watchdog halted, and how many finished.
std::pair<int, int> freshMotions(int motions) {
  robot::RunningBackend backend(std::make_unique<robot::SimulatedArm>(robot::twoObjects()),
                                benchOptions(4.0));
  int finished = 0;
  for (int i = 0; i < motions; ++i) {
    robot::RobotClient fresh(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                             robot::testKey());
    const auto events =
        robot::waitFor(fresh, i % 2 == 0 ? fresh.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06})
                                         : fresh.send(robot::MessageType::Drop, {0.10, 0.60, 0.0}));
    const robot::RobotEvent& last = robot::finalEvent(events);
    if (last.kind == robot::RobotEvent::Kind::Finished && last.outcome == robot::Outcome::Success)
      ++finished;
    if (backend.stats().watchdog_halts > 0) {
      robot::RobotClient reset(robot::Endpoint::resolve("127.0.0.1", backend.port()),
                               robot::testKey());
      robot::waitFor(reset, reset.send(robot::MessageType::Reset), 5s);
    }
  }
  return {static_cast<int>(backend.stats().watchdog_halts), finished};
}

// A fresh client's HOME through a link that delays 1.5 s (both ways, or towards the backend
// only): what became of it (refused with the reason, or ran).
std::string slowFreshHome(bool one_way) {
  Rig rig;
  test::UdpRelay relay(rig.backend.port(), robot::testKey(), 1234, true);
  relay.setDelay(1500ms, one_way);
  robot::RobotClient fresh(robot::Endpoint::resolve("127.0.0.1", relay.port()), robot::testKey());
  const auto events = robot::waitFor(fresh, fresh.send(robot::MessageType::Home), 30s);
  const robot::RobotEvent& last = robot::finalEvent(events);
  if (rig.backend.stats().executed > 0) return "ran: " + last.text;
  return std::string(robot::toString(last.kind)) + ": " + last.text;
}

// Only the flood, at a running backend, for timing the real `arbci robot stop` beside it.
int floodOnly(int port, double rate, double seconds) {
  Flood flood(port, 1, rate);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  std::printf("sent %llu forged datagrams to port %d\n",
              static_cast<unsigned long long>(flood.sent()), port);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "robot_link_bench: watchdog halts after a cut or a delayed link, false halts on a lossy "
      "link, STOP latency and false halts under a flood (loopback)"};
  int cuts = 30, lossy_runs = 10, stops = 50, flood_motions = 20;
  double flood_rate = 40000.0;
  app.add_option("--cuts", cuts, "link cuts (and as many delays) during a grasp")
      ->capture_default_str();
  app.add_option("--lossy-runs", lossy_runs, "grasps per loss rate (0: skip)")
      ->capture_default_str();
  app.add_option("--stops", stops, "STOPs timed with and without the flood")->capture_default_str();
  app.add_option("--flood-motions", flood_motions, "motions under the flood (false halts)")
      ->capture_default_str();
  app.add_option("--flood-rate", flood_rate, "forged datagrams a second")->capture_default_str();
  double watchdog_ms = g_watchdog_s * 1000.0;
  app.add_option("--watchdog-ms", watchdog_ms, "the backend's watchdog")->capture_default_str();
  bool log = false;
  app.add_flag("--log", log, "print the backends' log (every halt with its cause) to stderr");
  int fresh_stops = 20, fresh_motions = 100, flood_port = 0;
  double flood_seconds = 60.0;
  app.add_option("--fresh-stops", fresh_stops, "STOPs from fresh clients under the flood")
      ->capture_default_str();
  app.add_option("--fresh-motions", fresh_motions, "motions each from a fresh client (0: skip)")
      ->capture_default_str();
  app.add_option("--flood-port", flood_port, "only flood the backend at this port, then exit");
  app.add_option("--flood-seconds", flood_seconds, "how long --flood-port floods")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (flood_port > 0) return floodOnly(flood_port, flood_rate, flood_seconds);
  if (log) g_log = &std::cerr;
  g_watchdog_s = watchdog_ms / 1000.0;
  std::printf(
      "Watchdog halts during a grasp (watchdog %.0f ms, %d heartbeats per watchdog period; %s; "
      "the relay at real-time priority); ms as median / p95 / p99 / max\n",
      watchdog_ms, robot::ClientOptions{}.heartbeats_per_watchdog, loadText().c_str());
  std::printf(
      "| fault | runs | halted before the fault | halted | from the fault | from the last "
      "heartbeat's send time |\n"
      "|---|---|---|---|---|---|\n");
  const Latencies cut = halts(cuts, 1, [](test::UdpRelay& r) { r.setCut(true); });
  printHalts("link cut", cuts, cut);
  const Latencies delayed = halts(cuts, 101, [](test::UdpRelay& r) { r.setDelay(1500ms); });
  printHalts("link delayed 1.5 s", cuts, delayed);
  std::printf("target: every one halted within %.0f ms of the last heartbeat's send time\n\n",
              watchdog_ms);

  if (lossy_runs > 0) {
    std::printf(
        "A grasp (about 3 s) through a lossy link: how often the watchdog halts it (%s); the "
        "relay at real-time priority, a grasp in whose time the relay's own loop went %.0f ms "
        "without a turn counted apart: the bench, not the link, held its datagrams\n",
        loadText().c_str(), kRelayStallMs);
    std::printf(
        "| loss each way | grasps | halted by the watchdog | finished | relay stalled |\n"
        "|---|---|---|---|---|\n");
    for (const double loss : {0.1, 0.3, 0.5}) {
      int halted = 0, finished = 0, stalled = 0;
      for (int i = 0; i < lossy_runs; ++i) {
        Rig rig;
        test::UdpRelay relay(rig.backend.port(), robot::testKey(), static_cast<unsigned>(100 + i),
                             true);
        relay.setLoss(loss, loss);
        relay.takeLongestStallMs();
        robot::RobotClient client(robot::Endpoint::resolve("127.0.0.1", relay.port()),
                                  robot::testKey());
        const auto events =
            robot::waitFor(client, client.send(robot::MessageType::Grasp, {0.10, 0.60, 0.06}));
        const robot::RobotEvent& last = robot::finalEvent(events);
        if (last.kind == robot::RobotEvent::Kind::Finished &&
            last.outcome == robot::Outcome::Success)
          ++finished;
        halted += rig.backend.stats().watchdog_halts > 0 ? 1 : 0;
        stalled += relay.takeLongestStallMs() > kRelayStallMs;
      }
      std::printf("| %.0f %% | %d | %d | %d | %d |\n", loss * 100.0, lossy_runs, halted, finished,
                  stalled);
    }
    std::printf("\n");
  }

  std::printf(
      "STOP to ACCEPTED (ms, median / p99 / max) and false watchdog halts of live motions\n");
  std::printf(
      "| flood | STOPs | STOP to ACCEPTED | motions | false halts | forged sent | dropped unread "
      "|\n"
      "|---|---|---|---|---|---|---|\n");
  int status = cut.not_halted + delayed.not_halted == 0 ? 0 : 1;
  for (const double rate : {0.0, flood_rate}) {
    const FloodRow row = floodRow(rate, stops, flood_motions);
    std::printf(
        "| %.0f/s | %zu | %.2f / %.2f / %.2f | %d | %d | %llu | %llu |\n", rate, row.stop_ms.size(),
        percentile(row.stop_ms, 0.5), percentile(row.stop_ms, 0.99),
        row.stop_ms.empty() ? 0.0 : *std::max_element(row.stop_ms.begin(), row.stop_ms.end()),
        row.motions, row.false_halts, static_cast<unsigned long long>(row.sent),
        static_cast<unsigned long long>(row.shed));
    if (row.false_halts > 0) status = 1;
  }
  std::printf(
      "target: with 40,000 forged datagrams a second, STOP to ACCEPTED p99 <= 20 ms and "
      "0 false halts\n\n");

  if (fresh_stops > 0) {
    const std::vector<double> ms = freshStops(flood_rate, fresh_stops);
    const auto within = std::count_if(ms.begin(), ms.end(), [](double v) { return v <= 500.0; });
    std::printf(
        "A STOP from a fresh client (new address, from its first HELLO) under %.0f forged "
        "datagrams a second\n| tries | accepted within 500 ms | median / p95 / max ms |\n"
        "|---|---|---|\n| %d | %td | %.1f / %.1f / %.1f |\ntarget: 20 of 20 within 500 ms\n\n",
        flood_rate, fresh_stops, within, percentile(ms, 0.5), percentile(ms, 0.95),
        *std::max_element(ms.begin(), ms.end()));
    if (within < fresh_stops) status = 1;
  }
  if (fresh_motions > 0) {
    const auto [halts, finished] = freshMotions(fresh_motions);
    std::printf(
        "Healthy motions, each from a fresh client that sends it at once (as the CLI does; "
        "%s)\n"
        "| motions | finished | halted by the watchdog |\n|---|---|---|\n| %d | %d | %d |\n"
        "target: 0 halted\n\n",
        loadText().c_str(), fresh_motions, finished, halts);
    if (halts > 0) status = 1;
  }
  std::printf("A fresh client's HOME through a link that delays 1.5 s\n");
  std::printf("- both ways: %s\n", slowFreshHome(false).c_str());
  std::printf("- towards the backend only: %s\n", slowFreshHome(true).c_str());
  return status;
}
