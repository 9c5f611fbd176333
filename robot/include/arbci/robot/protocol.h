// The ARBCI robot protocol, version 2: UDP datagrams, little-endian, each authenticated with
// HMAC-SHA256 over its content under a shared key. A client binds its session to one run of the
// backend (HELLO/WELCOME: the backend's random boot id, carried by every later command), keeps
// a watchdog fed with HEARTBEATs while connected, and a STOP stays in force until a RESET.
// docs/robot-protocol.md describes it for anyone writing a backend.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace arbci::robot {

constexpr std::uint8_t kProtocolVersion = 2;
constexpr size_t kHeaderBytes = 42;
constexpr size_t kMacBytes = 32;
constexpr size_t kMaxDatagram = 1400;
constexpr int kMaxWorldObjects = 32;

enum class MessageType : std::uint8_t {
  // Commands (client to backend).
  Grasp = 1,
  Drop = 2,
  Home = 3,
  Stop = 4,
  Status = 5,
  Hello = 6,      // binds the session to this backend run and to the sender's address
  Reset = 7,      // ends a latched stop (an experimenter's decision)
  Heartbeat = 8,  // feeds the watchdog; carries the lowest command sequence still wanted
  // Replies (backend to client).
  Accepted = 0x81,
  Finished = 0x82,
  Rejected = 0x83,
  StatusReply = 0x84,
  Welcome = 0x85,  // answers HELLO; its header's boot field is the id every command must carry
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
  Cancelled = 10,    // the client gave up on it, or a STOP came after it: never runs
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
  std::uint32_t watchdog_ms = 0;                  // Welcome: the backend's watchdog (0: none)
  RejectReason reason = RejectReason::Malformed;  // Rejected
  Outcome outcome = Outcome::Success;             // Finished
  std::string text;                               // Rejected, Finished: for people
  StatusPayload status;                           // StatusReply
};

using Key = std::array<std::uint8_t, 32>;

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
// Never throws and never reads outside `size` bytes: any input yields a message or an error.
Decoded decode(const std::uint8_t* data, size_t size, const Key& key);

const char* toString(MessageType type);
const char* toString(RejectReason reason);
const char* toString(Outcome outcome);
const char* toString(RobotState state);
const char* toString(DecodeError error);
bool isCommand(MessageType type);
bool isMotion(MessageType type);  // GRASP, DROP, HOME: they move the arm

std::uint64_t wallClockMs();

}  // namespace arbci::robot
