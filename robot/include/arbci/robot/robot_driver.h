// What the backend drives: a real arm's driver or the simulated one. The backend checks each
// command with the driver before accepting it, then steps the driver until the command ends.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arbci/robot/protocol.h"

namespace arbci::robot {

struct DriverCommand {
  MessageType type = MessageType::Home;  // Grasp, Drop or Home
  Vec3 target;
};

struct Rejection {
  RejectReason reason;
  std::string text;
};

struct DriverResult {
  Outcome outcome = Outcome::Success;
  std::string text;
};

struct DriverStatus {
  RobotState state = RobotState::Idle;
  Vec3 tool;
  double gripper_opening = 1.0;
  int holding = -1;
  double progress = 0.0;
};

class RobotDriver {
 public:
  virtual ~RobotDriver() = default;
  // Why the command cannot be run now (workspace, reachability, state), or nothing.
  virtual std::optional<Rejection> check(const DriverCommand& command) const = 0;
  virtual void start(const DriverCommand& command) = 0;
  // Emergency stop: no further motion, at once.
  virtual void stop() = 0;
  // Advances by `seconds` of robot time; returns the result when the command has ended.
  virtual std::optional<DriverResult> step(double seconds) = 0;
  virtual DriverStatus status() const = 0;
  // The objects the driver knows (the simulated world; a real arm knows none).
  virtual std::vector<WorldObject> world() const = 0;
};

}  // namespace arbci::robot
