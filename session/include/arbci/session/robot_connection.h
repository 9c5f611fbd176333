// The session's robot link: a simulated backend (arbci-robotd, started here on 127.0.0.1 with a
// fresh key) or a remote one (host, port and key file from the session file), and the client that
// speaks the UDP protocol to it.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "arbci/robot/client.h"
#include "arbci/robot/robot_config.h"
#include "arbci/session/clock.h"
#include "arbci/session/robot_process.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

// Before the run: the key file a remote robot names exists; throws SessionConfigError naming the
// key and value (`session_file` first).
void checkRobotKey(const RobotSettings& settings, const std::string& session_file);

struct RobotLink {
  std::unique_ptr<RobotProcess> backend;  // arbci-robotd, for a simulated robot
  std::unique_ptr<robot::RobotClient> client;
  bool stepped = false;  // the arm moves on the session's simulated clock
};

// Simulated: starts arbci-robotd for `simulated_world` (its key, configuration, log and pid in
// `folder`), stepped when the session's clock is. Remote: loads the key. Throws
// std::runtime_error with the reason.
RobotLink connectRobot(const RobotSettings& settings, const robot::RobotConfig& simulated_world,
                       const std::filesystem::path& folder, const Clock& clock);

}  // namespace arbci::session
