// The ARBCI robot protocol, version 4: UDP datagrams, little-endian, each authenticated with
// HMAC-SHA256 over its content under a shared key. A client binds its session to one run of the
// backend by a challenge and response (HELLO with the client's nonce, WELCOME echoing it with
// the backend's, BIND echoing that: a replayed HELLO or BIND binds nothing, a replayed WELCOME is
// not taken), carries the run's boot id and stop epoch in its commands, keeps a watchdog fed with
// HEARTBEATs stamped with their send time on the backend's clock, and a STOP stays in force
// until a RESET, which starts a new stop epoch: nothing made before the STOP ever runs.
// docs/robot-protocol.md describes it for anyone writing a backend.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace arbci::robot {

constexpr std::uint8_t kProtocolVersion = 4;
constexpr size_t kHeaderBytes = 42;
constexpr size_t kMacBytes = 32;
constexpr size_t kMaxDatagram = 1400;
constexpr int kMaxWorldObjects = 32;
// A sequence this far below a session's highest is refused as a replay. Wide enough that a
// command retransmitted until the client gives up (15 s) stays inside it while heartbeats (at
// most 200 a second) and statuses (5) advance the highest.
constexpr std::uint64_t kReplayWindow = 4096;
// A session's heartbeats come at their rate (its heartbeat thread runs) once this many have
// arrived, the last two within half a watchdog of each other: the backend holds a motion until
// then, and a client sends one only after its heartbeat thread has sent this many.
constexpr int kStreamingHeartbeats = 3;

enum class MessageType : std::uint8_t {
  // Commands (client to backend).
  Grasp = 1,
  Drop = 2,
  Home = 3,
  Stop = 4,
  Status = 5,
  Hello = 6,      // asks for a WELCOME (a challenge); binds nothing by itself
  Reset = 7,      // ends a latched stop (an experimenter's decision) and starts a new stop epoch
  Heartbeat = 8,  // feeds the watchdog; carries its send time and the lowest sequence still wanted
  Bind = 9,       // answers a WELCOME's challenge: binds the session to this run and this address
  // Replies (backend to client).
  Accepted = 0x81,
  Finished = 0x82,
  Rejected = 0x83,
  StatusReply = 0x84,
  Welcome = 0x85,  // answers HELLO with a challenge; its boot field is the run's id
  Bound = 0x86,    // answers BIND: the session is bound to this run and address
  // Answers a HELLO whose MAC failed (another key): sealed with no key (kNoKey), so anyone can
  // forge one; it binds and moves nothing, and a client only reports it ("the key differs").
  KeyMismatch = 0x87,
};

enum class RejectReason : std::uint8_t {
  OutsideWorkspace = 1,
  Busy = 2,
  Malformed = 3,
  NotAuthenticated = 4,
  Replayed = 5,
  Unreachable = 6,
  InvalidState = 7,  // e.g. a DROP while holding nothing
  Stopped = 8,       // a latched stop is in force: RESET first
  UnknownBoot = 9,   // sent to another run of the backend (it restarted): HELLO again
  Cancelled = 10,    // the client gave up on it: never runs
  BeforeStop = 11,   // made before a STOP (an older stop epoch): never runs, also after a RESET
};

enum class Outcome : std::uint8_t { Success = 0, Failed = 1, Stopped = 2 };

// Stopped: a latched stop (STOP, or the watchdog) is in force; StatusPayload::stop_reason says
// which.
enum class RobotState : std::uint8_t { Idle = 0, Moving = 1, Stopped = 2, Fault = 3 };

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};

struct WorldObject {
  std::int32_t id = 0;
  Vec3 position;  // the centre of its top face, robot frame, metres
  bool held = false;
  // Its orientation (w, x, y, z; identity: upright, axes along the robot's), sent to 1/32767: a
  // physics driver's object can turn or topple.
  std::array<double, 4> orientation{1.0, 0.0, 0.0, 0.0};
};

struct StatusPayload {
  RobotState state = RobotState::Idle;
  Vec3 tool;
  double gripper_opening = 1.0;                       // 0 closed, 1 open
  std::int32_t holding = -1;                          // object id, -1: nothing
  MessageType current_command = MessageType::Status;  // Status: none
  std::uint64_t current_sequence = 0;
  bool current_is_yours = false;  // the running command is the asking session's
  double progress = 0.0;          // of the current command, 0-1
  // The last command of the asking session that finished, with its outcome.
  std::uint64_t last_finished_sequence = 0;
  Outcome last_outcome = Outcome::Success;
  std::string last_outcome_text;
  // Why motion commands are refused until a RESET ("emergency stop", "halted: link lost"); empty
  // when no stop is latched.
  std::string stop_reason;
  // The stop epoch motion commands must carry (RESET starts the next one).
  std::uint64_t stop_epoch = 0;
  // The backend's clock when it sent this (microseconds, steady): the client estimates the
  // offset between the clocks from it, for the send times its heartbeats carry.
  std::int64_t backend_time_us = 0;
  std::vector<WorldObject> objects;
};

struct Message {
  MessageType type = MessageType::Status;
  std::uint64_t session = 0;       // the client's random session id
  std::uint64_t sequence = 0;      // commands: the client's; replies: the command answered
  std::uint64_t timestamp_ms = 0;  // sender's wall clock (Unix time)
  // The backend's random id for its run: replies carry it, and so must every command but HELLO.
  std::uint64_t boot = 0;
  // Payloads (which one is used depends on `type`).
  Vec3 target;  // Grasp, Drop
  // Status, optional: the requester's clock (seconds); a stepped backend advances its robot to
  // it before answering, so a simulation runs on the session's clock.
  std::optional<double> clock_s;
  // Heartbeat: motion commands of this session below this sequence are abandoned by the client.
  std::uint64_t abandon_below = 0;
  // Grasp, Drop, Home: the stop epoch the client knew when it made the command; Welcome,
  // Accepted, Bound: the backend's current one.
  std::uint64_t stop_epoch = 0;
  // Hello: the client's fresh nonce; Welcome: that nonce, echoed.
  std::uint64_t nonce = 0;
  // Welcome: the backend's fresh nonce; Bind: that nonce, echoed.
  std::uint64_t challenge = 0;
  // Welcome: the backend's clock (microseconds, steady) when it sent it; Heartbeat: the send
  // time on the backend's clock as the client estimates it.
  std::int64_t time_us = 0;
  std::uint32_t watchdog_ms = 0;                  // Welcome: the backend's watchdog (0: none)
  RejectReason reason = RejectReason::Malformed;  // Rejected
  Outcome outcome = Outcome::Success;             // Finished
  std::string text;                               // Rejected, Finished: for people
  StatusPayload status;                           // StatusReply
};

using Key = std::array<std::uint8_t, 32>;
// The all-zero key KEY MISMATCH is sealed with: what the two sides share when their keys differ.
inline constexpr Key kNoKey{};

enum class DecodeError {
  None,
  TooShort,
  TooLong,
  BadMagic,
  BadVersion,
  BadReserved,
  BadLength,
  BadMac,
  BadType,
  BadPayload,
};

struct Decoded {
  DecodeError error = DecodeError::None;
  Message message;
  bool ok() const { return error == DecodeError::None; }
};

std::vector<std::uint8_t> encode(const Message& message, const Key& key);
// The header fields a backend may look at before spending a MAC on a datagram (a flood of
// forgeries is sorted by these); nothing when the datagram cannot be a message of this version.
struct Peek {
  MessageType type;
  std::uint64_t session;
};
std::optional<Peek> peek(const std::uint8_t* data, size_t size);
// Never throws and never reads outside `size` bytes: any input yields a message or an error.
Decoded decode(const std::uint8_t* data, size_t size, const Key& key);

const char* toString(MessageType type);
const char* toString(RejectReason reason);
const char* toString(Outcome outcome);
const char* toString(RobotState state);
const char* toString(DecodeError error);
bool isCommand(MessageType type);
bool isMotion(MessageType type);  // GRASP, DROP, HOME: they move the arm
std::int64_t steadyMicros();      // the monotonic clock the backend's times are on

std::uint64_t wallClockMs();

}  // namespace arbci::robot
