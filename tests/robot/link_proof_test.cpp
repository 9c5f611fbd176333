// The link proves itself before the arm moves, and a new client is heard whatever else arrives:
// a motion waits for its session's heartbeats to come at their rate (started when it comes fresh,
// refused when it comes stale or not at all), a flood from one address does not spend the budget of
// a new client at another, and the arm's state and refusals after a STOP and RESET say what is
// true. Real UDP on 127.0.0.1; every wait is bounded.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>

#include "support/raw_robot_session.h"
#include "support/robot_test_support.h"

namespace arbci::robot {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr Vec3 kObject1{0.10, 0.60, 0.06};

template <typename Done>
bool waitUntilTrue(Done done, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

BackendOptions withWatchdog(double first_heartbeat_wait_s) {
  BackendOptions options;
  options.speed_factor = 20.0;
  options.status_interval_s = 0.05;
  options.first_heartbeat_wait_s = first_heartbeat_wait_s;
  return options;
}

// The answer to command `sequence` is a refusal for `reason` whose text says `says`.
void expectRefused(RawSession& raw, std::uint64_t sequence, RejectReason reason,
                   const std::string& says, std::chrono::milliseconds wait = 2s) {
  const auto refused = raw.answer(sequence, wait);
  ASSERT_TRUE(refused) << "no answer to " << sequence;
  EXPECT_EQ(refused->type, MessageType::Rejected);
  EXPECT_EQ(refused->reason, reason);
  EXPECT_NE(refused->text.find(says), std::string::npos) << refused->text;
}

// A session bound by hand that has sent HOME 102 and no heartbeat yet.
struct WaitingHome {
  explicit WaitingHome(double first_heartbeat_wait_s)
      : backend(std::make_unique<SimulatedArm>(twoObjects()), withWatchdog(first_heartbeat_wait_s)),
        raw(backend.port()),
        bound(raw.hello(100)) {
    raw.send(raw.message(MessageType::Home, 102));
  }
  RunningBackend backend;
  RawSession raw;
  bool bound;
};

// A motion waits until the session's heartbeats come at their rate: one heartbeat (a client sends
// one as it binds) shows nothing of the thread that must go on feeding the watchdog.
TEST(RobotLinkProof, AMotionWaitsForTheSessionsHeartbeatsToComeAtTheirRateAndThenRuns) {
  WaitingHome w(60.0);
  ASSERT_TRUE(w.bound);
  RunningBackend& backend = w.backend;
  RawSession& raw = w.raw;
  raw.send(raw.message(MessageType::Home, 102));  // a retransmission while it waits
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(backend.stats().executed, 0u);
  raw.heartbeat(103);
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(backend.stats().executed, 0u);  // one heartbeat, then silence: still held
  raw.heartbeat(104);
  std::this_thread::sleep_for(5ms);
  raw.heartbeat(105);
  const auto accepted = raw.answer(102);
  ASSERT_TRUE(accepted);
  EXPECT_EQ(accepted->type, MessageType::Accepted);
  EXPECT_EQ(backend.stats().executed, 1u);
}

TEST(RobotLinkProof, AMotionWithNoHeartbeatIsRefusedAsUnreachable) {
  WaitingHome w(0.2);
  ASSERT_TRUE(w.bound);
  RunningBackend& backend = w.backend;
  RawSession& raw = w.raw;
  expectRefused(raw, 102, RejectReason::Unreachable,
                "the client's heartbeats did not come at their rate within 200 ms of its HOME (0 "
                "received)",
                5s);
  EXPECT_EQ(backend.stats().executed, 0u);
}

TEST(RobotLinkProof, AStaleFirstHeartbeatRefusesTheWaitingMotion) {
  WaitingHome w(60.0);
  ASSERT_TRUE(w.bound);
  RunningBackend& backend = w.backend;
  RawSession& raw = w.raw;
  raw.heartbeat(103, 750ms);  // what a slow link's heartbeat looks like on arrival
  expectRefused(raw, 102, RejectReason::Unreachable, "too slow to move safely");
  EXPECT_EQ(backend.stats().executed, 0u);
}

TEST(RobotLinkProof, AStopWhileAMotionWaitsRefusesIt) {
  WaitingHome w(60.0);
  ASSERT_TRUE(w.bound);
  RunningBackend& backend = w.backend;
  RawSession& raw = w.raw;
  std::this_thread::sleep_for(50ms);
  raw.send(raw.message(MessageType::Stop, 103));
  const auto refused = raw.answer(102);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->reason, RejectReason::Stopped);
  raw.heartbeat(104);
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(backend.stats().executed, 0u);
}

// Junk from one address as fast as it can go (the backend reads it all and verifies a few),
// while a new client at another address binds and stops the arm.
TEST(RobotLinkProof, ANewClientsStopGetsThroughAFloodFromAnotherAddress) {
  BackendOptions options = withWatchdog(1.0);
  options.unbound_per_s = 20.0;
  RunningBackend backend(std::make_unique<SimulatedArm>(twoObjects()), options);
  std::atomic<bool> flooding{true};
  std::thread flood([&] {
    UdpSocket socket;
    const auto to = Endpoint::resolve("127.0.0.1", backend.port());
    Message hello;
    hello.type = MessageType::Hello;
    hello.session = 77;
    hello.timestamp_ms = wallClockMs();
    Key wrong{};
    wrong[0] = 1;
    const auto forged = encode(hello, wrong);
    while (flooding) {
      for (int i = 0; i < 50; ++i) socket.sendTo(forged, to);
      std::this_thread::sleep_for(1ms);
    }
  });
  ASSERT_TRUE(waitUntilTrue([&] { return backend.stats().shed > 100; }, 5s));
  RobotClient client(Endpoint::resolve("127.0.0.1", backend.port()), testKey());
  const auto events = waitFor(client, client.send(MessageType::Stop), 10s);
  flooding = false;
  flood.join();
  EXPECT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished) << finalEvent(events).text;
}

TEST(RobotLinkProof, AfterAStopDuringAMotionAndAResetTheArmIsIdle) {
  BackendOptions options = withWatchdog(1.0);
  options.speed_factor = 1.0;  // the grasp lasts seconds: the STOP comes during it
  RunningBackend backend(std::make_unique<SimulatedArm>(twoObjects()), options);
  RobotClient client(Endpoint::resolve("127.0.0.1", backend.port()), testKey());
  ASSERT_TRUE(waitUntilAccepted(client, client.send(MessageType::Grasp, kObject1)));
  waitFor(client, client.send(MessageType::Stop));
  waitFor(client, client.send(MessageType::Reset));
  // A status made after the RESET carries its stop epoch (2).
  client.requestStatus();
  ASSERT_TRUE(waitUntilTrue(
      [&] {
        client.poll();
        return client.status() && client.status()->stop_epoch == 2;
      },
      5s));
  EXPECT_TRUE(client.status()->stop_reason.empty()) << client.status()->stop_reason;
  EXPECT_EQ(client.status()->state, RobotState::Idle);
}

TEST(RobotLinkProof, AMotionWithoutAStopEpochOrWithAFutureOneIsRefusedSayingWhich) {
  RunningBackend backend(std::make_unique<SimulatedArm>(twoObjects()), withWatchdog(60.0));
  RawSession raw(backend.port());
  ASSERT_TRUE(raw.hello(100));
  raw.heartbeat(102);
  Message none = raw.message(MessageType::Home, 103);
  none.stop_epoch = 0;
  raw.send(none);
  expectRefused(raw, 103, RejectReason::BeforeStop, "carries no stop epoch (0)");
  Message future = raw.message(MessageType::Home, 104);
  future.stop_epoch = 7;
  raw.send(future);
  expectRefused(raw, 104, RejectReason::BeforeStop, "has not reached (epoch now 1)");
}

}  // namespace
}  // namespace arbci::robot
