// The robot link when things go wrong, over real UDP on 127.0.0.1 through a relay that loses,
// cuts, holds back and captures datagrams: a command is bound to one backend run (a replay after
// a restart never runs; a restart never runs a command twice), a STOP stays in force until a
// RESET, the watchdog halts the arm when the link is cut, a command given up never starts later,
// and the replay window, reply address and receive buffer hold at their edges. Every wait is
// bounded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <thread>

#include "arbci/robot/mujoco_arm.h"
#include "support/halt_recording_arm.h"
#include "support/raw_robot_session.h"
#include "support/robot_test_support.h"
#include "support/udp_relay.h"

namespace arbci::robot {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr Vec3 kObject1{0.10, 0.60, 0.06}, kObject2{-0.15, 0.55, 0.06};

Endpoint local(int port) {
  return Endpoint::resolve("127.0.0.1", port);
}

bool waitUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout = 5s) {
  const auto end = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

bool connect(RobotClient& client) {
  const auto end = Clock::now() + 5s;
  while (!client.connected() && Clock::now() < end) {
    client.poll();
    std::this_thread::sleep_for(1ms);
  }
  return client.connected();
}

// The backend's rejection of command `sequence`, as the relay saw it go back (up to 3 s).
std::optional<Message> rejectionSeen(const test::UdpRelay& relay, std::uint64_t sequence) {
  std::optional<Message> found;
  waitUntil(
      [&] {
        for (const Message& m : relay.replies()) {
          if (m.type == MessageType::Rejected && m.sequence == sequence) found = m;
        }
        return found.has_value();
      },
      3s);
  return found;
}

// A backend on the wall clock at real speed (a grasp takes seconds), pushing status often.
BackendOptions realTime() {
  BackendOptions options;
  options.status_interval_s = 0.05;
  options.speed_factor = 1.0;
  return options;
}

bool has(const std::vector<RobotEvent>& events, RobotEvent::Kind kind) {
  return std::any_of(events.begin(), events.end(),
                     [&](const RobotEvent& e) { return e.kind == kind; });
}

TEST(RobotLink, ACapturedCommandReplayedToARestartedBackendIsRejected) {
  auto first = std::make_unique<RunningBackend>(20.0);
  const int port = first->port();
  std::vector<test::UdpRelay::Bytes> captured;
  {
    test::UdpRelay relay(port, testKey());
    RobotClient client(local(relay.port()), testKey(), fastClient());
    const auto events = waitFor(client, client.send(MessageType::Grasp, kObject1));
    ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished);
    captured = relay.captured(MessageType::Grasp);
  }
  ASSERT_FALSE(captured.empty());
  const std::uint64_t first_boot = first->boot();
  first.reset();
  RunningBackend second(20.0, port);
  EXPECT_NE(second.boot(), first_boot);
  // Five copies at different ages, as an attacker would try them.
  UdpSocket attacker;
  for (int i = 0; i < 5; ++i) {
    attacker.sendTo(captured[static_cast<size_t>(i) % captured.size()], local(port));
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_TRUE(backendReceived(second, 5));
  EXPECT_EQ(second.stats().executed, 0u);
  EXPECT_EQ(second.stats().replayed, 5u);
  // What came back to the sender's address: only refusals smaller than what was sent (the
  // backend cannot be used to amplify traffic towards a forged address).
  size_t sent_bytes = 0, received_bytes = 0;
  for (int i = 0; i < 5; ++i)
    sent_bytes += captured[static_cast<size_t>(i) % captured.size()].size();
  const auto quiet_until = Clock::now() + 300ms;
  while (Clock::now() < quiet_until) {
    attacker.wait(2);
    while (auto d = attacker.receive()) {
      EXPECT_LT(d->bytes.size(), captured.front().size());
      received_bytes += d->bytes.size();
    }
  }
  EXPECT_LT(received_bytes, sent_bytes) << received_bytes << " of " << sent_bytes << " bytes";
  RobotClient observer(local(port), testKey(), fastClient());
  const StatusPayload status = freshStatus(observer);
  EXPECT_EQ(status.holding, -1);
  ASSERT_EQ(status.objects.size(), 2u);
  EXPECT_NEAR(status.objects[0].position.x, kObject1.x, 1e-9);  // never touched
  EXPECT_EQ(status.state, RobotState::Idle);
}

TEST(RobotLink, LostAcceptancesAndARestartRunTheCommandAtMostOnce) {
  auto first = std::make_unique<RunningBackend>(1.0);  // real time: the grasp takes seconds
  const int port = first->port();
  test::UdpRelay relay(port, testKey());
  relay.dropReplies({MessageType::Accepted, MessageType::StatusReply, MessageType::Finished});
  RobotClient client(local(relay.port()), testKey(), fastClient());
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  std::vector<RobotEvent> events;
  ASSERT_TRUE(waitUntil([&] {
    client.poll();
    for (RobotEvent& e : client.takeEvents()) events.push_back(std::move(e));
    return first->stats().executed == 1;
  }));
  for (RobotEvent& e : pollFor(client, 300ms)) events.push_back(std::move(e));  // retransmits
  first.reset();  // killed mid-grasp, its acceptances all lost
  RunningBackend second(1.0, port);
  for (RobotEvent& e : waitFor(client, grasp, 5s)) events.push_back(std::move(e));
  ASSERT_FALSE(events.empty());
  const auto failed = std::find_if(events.begin(), events.end(), [&](const RobotEvent& e) {
    return e.sequence == grasp && e.kind == RobotEvent::Kind::Failed;
  });
  ASSERT_NE(failed, events.end());
  EXPECT_NE(failed->text.find("restarted"), std::string::npos) << failed->text;
  EXPECT_TRUE(has(events, RobotEvent::Kind::Restarted));
  EXPECT_FALSE(has(events, RobotEvent::Kind::Finished));
  pollFor(client, 500ms);
  EXPECT_EQ(second.stats().executed, 0u);  // once in all: on the first run only
  EXPECT_TRUE(client.connected());         // bound to the new run
}

// With every ACCEPTED lost, the status's running command tells the client its command runs: it
// stops retransmitting, and the command finishes once.
TEST(RobotLink, AcceptanceIsReadFromTheStatusWhenEveryAcceptedIsLost) {
  RunningBackend backend(5.0);
  test::UdpRelay relay(backend.port(), testKey());
  relay.dropReplies({MessageType::Accepted});
  RobotClient client(local(relay.port()), testKey(), fastClient());
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  ASSERT_TRUE(waitUntilAccepted(client, grasp));
  EXPECT_TRUE(client.accepted(grasp));
  EXPECT_TRUE(client.busy());  // known accepted while it runs, not only when it finished
  const std::uint64_t copies = backend.stats().duplicates;
  pollFor(client, 300ms);
  EXPECT_EQ(backend.stats().duplicates, copies);  // no more retransmissions
  const auto events = waitFor(client, grasp, 10s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished);
  EXPECT_EQ(finalEvent(events).outcome, Outcome::Success);
  EXPECT_EQ(backend.stats().executed, 1u);
  for (const Message& m : relay.replies()) EXPECT_NE(m.type, MessageType::Rejected);
}

TEST(RobotLink, AStopStaysInForceUntilAResetAndEarlierCommandsNeverRun) {
  RunningBackend backend(20.0);
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient client(local(relay.port()), testKey(), fastClient());
  ASSERT_TRUE(connect(client));
  relay.hold(MessageType::Grasp);
  const std::uint64_t a = client.send(MessageType::Grasp, kObject1);
  const std::uint64_t b = client.send(MessageType::Grasp, kObject2);
  pollFor(client, 100ms);
  const std::uint64_t stop = client.send(MessageType::Stop);
  const auto events = waitFor(client, stop, 3s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished);
  // The client cannot know whether the backend got the two GRASPs: they stay pending until the
  // backend says.
  EXPECT_TRUE(client.busy());
  // An earlier GRASP delivered after the STOP: refused, the stop is latched; the client is told.
  relay.release(a);
  const auto refused = waitFor(client, a, 3s);
  ASSERT_EQ(finalEvent(refused).kind, RobotEvent::Kind::Rejected) << finalEvent(refused).text;
  EXPECT_EQ(finalEvent(refused).reason, RejectReason::Stopped) << finalEvent(refused).text;
  EXPECT_EQ(freshStatus(client).stop_reason, "emergency stop");
  const std::uint64_t epoch = client.stopEpoch();
  const auto reset = waitFor(client, client.send(MessageType::Reset), 3s);
  ASSERT_EQ(finalEvent(reset).kind, RobotEvent::Kind::Finished);
  EXPECT_EQ(client.stopEpoch(), epoch + 1);
  // After the RESET, a GRASP made before the STOP still never runs.
  relay.release(b);
  const auto late = waitFor(client, b, 3s);
  ASSERT_EQ(finalEvent(late).kind, RobotEvent::Kind::Rejected) << finalEvent(late).text;
  EXPECT_EQ(finalEvent(late).reason, RejectReason::BeforeStop) << finalEvent(late).text;
  EXPECT_EQ(backend.stats().executed, 0u);
  // A new GRASP works.
  relay.stopHolding();
  const auto fresh = waitFor(client, client.send(MessageType::Grasp, kObject1));
  ASSERT_EQ(finalEvent(fresh).kind, RobotEvent::Kind::Finished) << finalEvent(fresh).text;
  EXPECT_EQ(finalEvent(fresh).outcome, Outcome::Success);
  EXPECT_EQ(backend.stats().executed, 1u);
  EXPECT_TRUE(freshStatus(client).stop_reason.empty());
}

// The STOP is global: another client's GRASP, made before the STOP and held back by the network
// until after the RESET, never runs, and its client is told why.
TEST(RobotLink, AnotherClientsCommandMadeBeforeAStopNeverRunsAfterTheReset) {
  RunningBackend backend(20.0);
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient other(local(relay.port()), testKey(), fastClient());
  RobotClient experimenter(local(backend.port()), testKey(), fastClient());
  ASSERT_TRUE(connect(other));
  ASSERT_TRUE(connect(experimenter));
  relay.hold(MessageType::Grasp);
  const std::uint64_t grasp = other.send(MessageType::Grasp, kObject1);
  pollFor(other, 100ms);
  ASSERT_EQ(finalEvent(waitFor(experimenter, experimenter.send(MessageType::Stop), 3s)).kind,
            RobotEvent::Kind::Finished);
  ASSERT_EQ(finalEvent(waitFor(experimenter, experimenter.send(MessageType::Reset), 3s)).kind,
            RobotEvent::Kind::Finished);
  pollFor(other, 300ms);  // the other client hears of the new epoch through its statuses
  relay.release(grasp);
  const auto events = waitFor(other, grasp, 3s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Rejected) << finalEvent(events).text;
  EXPECT_EQ(finalEvent(events).reason, RejectReason::BeforeStop);
  EXPECT_NE(finalEvent(events).text.find("before the STOP"), std::string::npos)
      << finalEvent(events).text;
  EXPECT_EQ(backend.stats().executed, 0u);
  // Its next command, made after the RESET, runs.
  relay.stopHolding();
  const auto next = waitFor(other, other.send(MessageType::Grasp, kObject1));
  EXPECT_EQ(finalEvent(next).kind, RobotEvent::Kind::Finished) << finalEvent(next).text;
  EXPECT_EQ(backend.stats().executed, 1u);
}

// The watchdog's proof, for any driver: a cut link halts the arm and latches the stop.
void watchdogHaltsWhenTheLinkIsCut(std::unique_ptr<RobotDriver> arm) {
  auto halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  BackendOptions options = realTime();
  ASSERT_DOUBLE_EQ(options.watchdog_s, 0.1);  // the default (robot.watchdog_ms)
  RunningBackend backend(std::make_unique<test::HaltRecordingArm>(std::move(arm), halted_at),
                         options);
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient client(local(relay.port()), testKey(), fastClient());
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  ASSERT_TRUE(waitUntilAccepted(client, grasp));
  pollFor(client, 300ms);  // moving, heartbeats flowing
  ASSERT_EQ(*halted_at, 0);
  const Clock::time_point cut = Clock::now();
  relay.setCut(true);
  const Clock::time_point give_up = cut + 10s;
  while (*halted_at == 0 && Clock::now() < give_up) std::this_thread::sleep_for(1ms);
  ASSERT_NE(*halted_at, 0) << "the arm was not halted";
  // The watchdog, not the grasp's end, stopped it: the outcome below is "stopped", "link lost".
  // How soon is measured in bench/ (watchdog_bench, robot_link_bench), not judged here.
  relay.setCut(false);
  const auto events = waitFor(client, grasp, 5s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished);
  EXPECT_EQ(finalEvent(events).outcome, Outcome::Stopped);
  EXPECT_NE(finalEvent(events).text.find("link lost"), std::string::npos);
  const StatusPayload halted = freshStatus(client);
  EXPECT_EQ(halted.state, RobotState::Stopped);
  EXPECT_EQ(halted.stop_reason, "halted: link lost");
  EXPECT_EQ(backend.stats().watchdog_halts, 1u);
  std::this_thread::sleep_for(200ms);
  const StatusPayload later = freshStatus(client);
  EXPECT_EQ(later.tool.x, halted.tool.x);  // still where it halted
  EXPECT_EQ(later.tool.z, halted.tool.z);
  // Latched: a motion needs a RESET first.
  auto next = waitFor(client, client.send(MessageType::Home), 3s);
  EXPECT_EQ(finalEvent(next).reason, RejectReason::Stopped);
  ASSERT_EQ(finalEvent(waitFor(client, client.send(MessageType::Reset), 3s)).kind,
            RobotEvent::Kind::Finished);
  next = waitFor(client, client.send(MessageType::Home), 15s);
  EXPECT_EQ(finalEvent(next).kind, RobotEvent::Kind::Finished);
  EXPECT_EQ(finalEvent(next).outcome, Outcome::Success);
}

TEST(RobotLink, TheWatchdogHaltsTheArmWhenTheLinkIsCut) {
  watchdogHaltsWhenTheLinkIsCut(std::make_unique<SimulatedArm>(twoObjects()));
}

TEST(RobotLink, TheWatchdogHaltsTheMujocoArmWhenTheLinkIsCut) {
  watchdogHaltsWhenTheLinkIsCut(std::make_unique<MujocoArm>(twoObjects()));
}

// A link that starts delaying everything by 1.5 s mid-grasp halts the arm as a cut one does:
// the heartbeats carry their send time, and one that arrives older than the watchdog feeds
// nothing. While the link stays that slow, a new motion is refused with the reason.
TEST(RobotLink, TheWatchdogHaltsTheArmWhenTheLinkIsDelayed) {
  auto halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  BackendOptions options = realTime();
  RunningBackend backend(std::make_unique<test::HaltRecordingArm>(twoObjects(), halted_at),
                         options);
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient client(local(relay.port()), testKey(), fastClient());
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  ASSERT_TRUE(waitUntilAccepted(client, grasp));
  pollFor(client, 300ms);  // moving, heartbeats flowing
  ASSERT_EQ(*halted_at, 0);
  ASSERT_TRUE(client.clockOffsetUs().has_value());
  const Clock::time_point delayed = Clock::now();
  relay.setDelay(1500ms);
  const Clock::time_point give_up = delayed + 10s;
  while (*halted_at == 0 && Clock::now() < give_up) std::this_thread::sleep_for(1ms);
  ASSERT_NE(*halted_at, 0) << "the arm was not halted";
  const auto events = waitFor(client, grasp, 8s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Finished);
  EXPECT_EQ(finalEvent(events).outcome, Outcome::Stopped);
  EXPECT_NE(finalEvent(events).text.find("link lost"), std::string::npos);
  EXPECT_EQ(backend.stats().watchdog_halts, 1u);
  EXPECT_GT(backend.stats().stale_heartbeats, 0u);  // the delayed ones came, and fed nothing
  // Still 1.5 s late: after a RESET, a HOME is refused (the watchdog could not protect it).
  ASSERT_EQ(finalEvent(waitFor(client, client.send(MessageType::Reset), 8s)).kind,
            RobotEvent::Kind::Finished);
  const auto home = waitFor(client, client.send(MessageType::Home), 8s);
  ASSERT_EQ(finalEvent(home).kind, RobotEvent::Kind::Rejected) << finalEvent(home).text;
  EXPECT_NE(finalEvent(home).text.find("too slow"), std::string::npos) << finalEvent(home).text;
  EXPECT_EQ(backend.stats().executed, 1u);
}

// A STOP, a RESET and a watchdog halt in quick succession: each is in the backend's log once,
// with its cause (a halt right after a STOP's line was once dropped by the log's flood limit).
TEST(RobotLink, EveryStopResetAndHaltIsLoggedOnceWithItsCause) {
  std::ostringstream log;
  BackendOptions options = realTime();
  options.log = &log;
  auto halted_at = std::make_shared<std::atomic<Clock::rep>>(0);
  RunningBackend backend(std::make_unique<test::HaltRecordingArm>(twoObjects(), halted_at),
                         options);
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient client(local(relay.port()), testKey(), fastClient());
  ASSERT_EQ(finalEvent(waitFor(client, client.send(MessageType::Stop), 3s)).kind,
            RobotEvent::Kind::Finished);
  ASSERT_EQ(finalEvent(waitFor(client, client.send(MessageType::Reset), 3s)).kind,
            RobotEvent::Kind::Finished);
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  ASSERT_TRUE(waitUntilAccepted(client, grasp));
  halted_at->store(0);  // the STOP's halt is behind us
  relay.setCut(true);   // the client's heartbeats stop arriving: the watchdog halts the grasp
  const Clock::time_point give_up = Clock::now() + 10s;
  while (*halted_at == 0 && Clock::now() < give_up) std::this_thread::sleep_for(1ms);
  ASSERT_NE(*halted_at, 0) << "the arm was not halted";
  backend.halt();  // its thread has written all it will
  const std::string text = log.str();
  auto count = [&](const std::string& line) {
    int n = 0;
    for (size_t at = text.find(line); at != std::string::npos; at = text.find(line, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("stopped: emergency stop"), 1) << text;
  EXPECT_EQ(count("RESET: the stop (emergency stop) is lifted"), 1) << text;
  EXPECT_EQ(count("stopped: halted: link lost (GRASP halted)"), 1) << text;
}

TEST(RobotLink, ACommandTheClientGaveUpOnNeverStartsLater) {
  RunningBackend backend(20.0);
  test::UdpRelay relay(backend.port(), testKey());
  ClientOptions options = fastClient();
  options.give_up_s = 0.5;
  RobotClient client(local(relay.port()), testKey(), options);
  ASSERT_TRUE(connect(client));
  relay.hold(MessageType::Grasp);
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  const auto events = waitFor(client, grasp, 3s);
  ASSERT_EQ(finalEvent(events).kind, RobotEvent::Kind::Failed);
  EXPECT_TRUE(finalEvent(events).may_have_run);  // it was sent: the backend may have it
  EXPECT_NE(finalEvent(events).text.find("will not start it later"), std::string::npos)
      << finalEvent(events).text;
  pollFor(client, 100ms);  // heartbeats tell the backend what the client gave up
  relay.release(grasp);    // the copies arrive late
  const auto refused = rejectionSeen(relay, grasp);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->reason, RejectReason::Cancelled) << refused->text;
  EXPECT_EQ(backend.stats().executed, 0u);
}

TEST(RobotLink, TheReplayWindowHoldsAtTheTopOfTheSequenceRange) {
  RunningBackend backend(50.0);
  RawSession raw(backend.port());
  constexpr std::uint64_t kTop = std::numeric_limits<std::uint64_t>::max();
  ASSERT_TRUE(raw.hello(kTop - 2 * kReplayWindow));
  // The link proven (a motion waits until the session's heartbeats come at their rate; both
  // clocks are this machine's), a command at the very top runs once, however many copies arrive.
  for (int i = kStreamingHeartbeats; i >= 1; --i) {
    Message heartbeat = raw.message(MessageType::Heartbeat, kTop - static_cast<std::uint64_t>(i));
    heartbeat.time_us = steadyMicros();
    raw.send(heartbeat);
    std::this_thread::sleep_for(10ms);
  }
  const Message home = raw.message(MessageType::Home, kTop);
  for (int i = 0; i < 3; ++i) raw.send(home);
  const auto accepted = raw.answer(kTop);
  ASSERT_TRUE(accepted);
  EXPECT_EQ(accepted->type, MessageType::Accepted);
  ASSERT_TRUE(waitUntil([&] { return backend.stats().duplicates >= 2; }));
  for (int i = 0; i < 3; ++i) raw.send(home);
  ASSERT_TRUE(waitUntil([&] { return backend.stats().duplicates >= 5; }));
  EXPECT_EQ(backend.stats().executed, 1u);
  // A whole window below the highest: refused as a replay; just inside it: a new command.
  raw.send(raw.message(MessageType::Status, kTop - kReplayWindow));
  const auto old = raw.answer(kTop - kReplayWindow);
  ASSERT_TRUE(old);
  EXPECT_EQ(old->type, MessageType::Rejected);
  EXPECT_EQ(old->reason, RejectReason::Replayed);
  raw.send(raw.message(MessageType::Status, kTop - kReplayWindow + 1));
  const auto inside = raw.answer(kTop - kReplayWindow + 1, 2s);
  EXPECT_FALSE(inside && inside->type == MessageType::Rejected);
}

TEST(RobotLink, RepliesGoOnlyToTheAddressBoundByTheChallenge) {
  RunningBackend backend(20.0);
  RawSession raw(backend.port());
  ASSERT_TRUE(raw.hello(100));  // HELLO 100, BIND 101
  UdpSocket other;
  // An authenticated STATUS from another address is answered at the bound address.
  raw.send(raw.message(MessageType::Status, 102), other);
  const auto answer = raw.answer(102);
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->type, MessageType::StatusReply);
  EXPECT_FALSE(raw.receive(200ms, other));
  // A replayed HELLO from the other address does not move the binding (nor is it answered:
  // not newer than the session's last).
  Message hello = raw.message(MessageType::Hello, 100);
  hello.nonce = 0x1234 + 100;
  raw.send(hello, other);
  raw.send(raw.message(MessageType::Status, 103), other);
  EXPECT_FALSE(raw.receive(300ms, other));
  const auto still = raw.answer(103);
  ASSERT_TRUE(still);
  EXPECT_EQ(still->type, MessageType::StatusReply);
}

// A bound client says HELLO again (after silence, or a new address) while its heartbeats go on:
// its BIND carries a sequence below those heartbeats' and is still taken (unused, inside the
// replay window); a second copy of that BIND is answered again, not bound anew.
TEST(RobotLink, ARebindingClientsBindIsTakenAfterItsHeartbeats) {
  RunningBackend backend(20.0);
  RawSession raw(backend.port());
  ASSERT_TRUE(raw.hello(100));  // HELLO 100, BIND 101
  Message hello = raw.message(MessageType::Hello, 102);
  hello.nonce = 777;
  raw.send(hello);
  const auto welcome = raw.answer(102);
  ASSERT_TRUE(welcome);
  ASSERT_EQ(welcome->type, MessageType::Welcome);
  raw.send(raw.message(MessageType::Heartbeat, 110));  // heartbeats went on meanwhile
  raw.send(raw.message(MessageType::Status, 111));
  ASSERT_TRUE(raw.answer(111));
  Message bind = raw.message(MessageType::Bind, 103);
  bind.challenge = welcome->challenge;
  raw.send(bind);
  const auto bound = raw.answer(103);
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->type, MessageType::Bound);
  raw.send(bind);  // its BOUND lost: the copy is answered from the binding
  const auto again = raw.answer(103);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->type, MessageType::Bound);
}

// A captured HELLO replayed to a restarted backend gets a WELCOME, but without the key nobody can
// answer its challenge: nothing is bound, and the real client binds as before. A captured BIND
// replayed binds nothing either (its challenge is spent, or belongs to another run).
TEST(RobotLink, AReplayedHelloOrBindBindsNothing) {
  auto first = std::make_unique<RunningBackend>(20.0);
  const int port = first->port();
  std::vector<test::UdpRelay::Bytes> hellos, binds;
  {
    test::UdpRelay relay(port, testKey());
    RobotClient client(local(relay.port()), testKey(), fastClient());
    ASSERT_TRUE(connect(client));
    hellos = relay.captured(MessageType::Hello);
    binds = relay.captured(MessageType::Bind);
  }
  ASSERT_FALSE(hellos.empty());
  ASSERT_FALSE(binds.empty());
  // Replayed to the same run: the BIND's challenge is spent.
  UdpSocket attacker;
  const std::uint64_t replayed = first->stats().replayed;
  for (const auto& bind : binds) attacker.sendTo(bind, local(port));
  ASSERT_TRUE(waitUntil([&] { return first->stats().replayed >= replayed + binds.size(); }));
  first.reset();
  RunningBackend second(20.0, port);
  // To a restarted run: the HELLO is answered (a WELCOME no larger than it), the BIND refused.
  for (const auto& hello : hellos) attacker.sendTo(hello, local(port));
  for (const auto& bind : binds) attacker.sendTo(bind, local(port));
  std::optional<Datagram> welcome;
  waitUntil(
      [&] {
        attacker.wait(2);
        while (auto d = attacker.receive()) {
          const Decoded decoded = decode(d->bytes.data(), d->bytes.size(), testKey());
          if (decoded.ok() && decoded.message.type == MessageType::Welcome) welcome = d;
        }
        return welcome.has_value();
      },
      2s);
  ASSERT_TRUE(welcome);
  EXPECT_LE(welcome->bytes.size(), hellos.front().size());  // no amplification
  // Nothing is bound: a status asked with the replayed session's id is refused or ignored.
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(second.stats().executed, 0u);
  RobotClient client(local(port), testKey(), fastClient());
  ASSERT_TRUE(connect(client));
  EXPECT_EQ(finalEvent(waitFor(client, client.send(MessageType::Home), 10s)).kind,
            RobotEvent::Kind::Finished);
}

// A STATUS reply of an earlier backend run, replayed to the client, is not taken for a restart:
// the client asks (a fresh HELLO), the backend it is bound to answers with the same run, and the
// pending command goes on.
TEST(RobotLink, AReplayedReplyFromAnEarlierRunIsNotARestart) {
  std::vector<test::UdpRelay::Bytes> old_replies;
  Endpoint old_backend;
  {
    RunningBackend first(20.0);
    test::UdpRelay relay(first.port(), testKey());
    RobotClient client(local(relay.port()), testKey(), fastClient());
    ASSERT_TRUE(connect(client));
    freshStatus(client);
    old_replies = relay.capturedReplies(MessageType::StatusReply);
  }
  ASSERT_FALSE(old_replies.empty());
  RunningBackend backend(1.0);  // real time: the grasp takes seconds
  test::UdpRelay relay(backend.port(), testKey());
  RobotClient client(local(relay.port()), testKey(), fastClient());
  const std::uint64_t grasp = client.send(MessageType::Grasp, kObject1);
  ASSERT_TRUE(waitUntilAccepted(client, grasp));
  std::vector<RobotEvent> events;
  for (int i = 0; i < 4; ++i) {
    relay.injectReply(old_replies.back());  // as if from the backend's address
    for (RobotEvent& e : pollFor(client, 100ms)) events.push_back(std::move(e));
  }
  EXPECT_FALSE(has(events, RobotEvent::Kind::Restarted));
  EXPECT_FALSE(has(events, RobotEvent::Kind::Failed));
  EXPECT_TRUE(client.connected());
  EXPECT_TRUE(client.busy());  // the grasp still runs
  EXPECT_EQ(backend.stats().watchdog_halts, 0u);
}

// Bursts of junk datagrams of the largest size, then a STATUS retransmitted as a client does:
// answered after each burst (the kernel drops what overflows the receive buffer, which is kept
// small so a flood becomes loss, never a long queue in front of a STOP).
TEST(RobotLink, AStatusAfterBurstsOfJunkIsAnswered) {
  RunningBackend backend(20.0);
  RawSession raw(backend.port());
  ASSERT_TRUE(raw.hello(1));
  UdpSocket junk;
  const std::vector<std::uint8_t> bytes(kMaxDatagram, 0x5a);
  std::uint64_t sequence = 10;
  for (const int burst : {250, 1000, 4000}) {
    for (int i = 0; i < burst; ++i) junk.sendTo(bytes, local(backend.port()));
    ++sequence;
    std::optional<Message> reply;
    for (int attempt = 0; attempt < 40 && !reply; ++attempt) {
      raw.send(raw.message(MessageType::Status, sequence));
      reply = raw.answer(sequence, 50ms);
    }
    ASSERT_TRUE(reply) << "after a burst of " << burst << " (receive buffer "
                       << backend.backend().receiveBufferBytes() / 1024 << " KiB, "
                       << backend.stats().shed << " dropped unread)";
    EXPECT_EQ(reply->type, MessageType::StatusReply);
  }
}

}  // namespace
}  // namespace arbci::robot
