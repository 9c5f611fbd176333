// The ARBCI robot protocol, version 1: UDP datagrams, little-endian, each authenticated with
// HMAC-SHA256 over its content under a shared key. docs/robot-protocol.md describes it for
// anyone writing a backend.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace arbci::robot {

constexpr std::uint8_t kProtocolVersion = 1;
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
  // Replies (backend to client).
  Accepted = 0x81,
  Finished = 0x82,
  Rejected = 0x83,
  StatusReply = 0x84,
};

enum class RejectReason : std::uint8_t {
  OutsideWorkspace = 1,
  Busy = 2,
  Malformed = 3,
  NotAuthenticated = 4,
  Replayed = 5,
  Unreachable = 6,
  InvalidState = 7,  // e.g. a DROP while holding nothing
};

enum class Outcome : std::uint8_t { Success = 0, Failed = 1, Stopped = 2 };

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
  double progress = 0.0;  // of the current command, 0-1
  // The last command of the asking session that finished, with its outcome.
  std::uint64_t last_finished_sequence = 0;
  Outcome last_outcome = Outcome::Success;
  std::string last_outcome_text;
  std::vector<WorldObject> objects;
};

struct Message {
  MessageType type = MessageType::Status;
  std::uint64_t session = 0;       // the client's random session id
  std::uint64_t sequence = 0;      // commands: the client's; replies: the command answered
  std::uint64_t timestamp_ms = 0;  // sender's wall clock (Unix time)
  std::uint64_t boot = 0;          // replies: the backend's random id for this run
  // Payloads (which one is used depends on `type`).
  Vec3 target;  // Grasp, Drop
  // Status, optional: the requester's clock (seconds); a stepped backend advances its robot to
  // it before answering, so a simulation runs on the session's clock.
  std::optional<double> clock_s;
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

std::uint64_t wallClockMs();

}  // namespace arbci::robot
