// The windowed workstation: the experimenter window (panels over the running session) and,
// when the session names a monitor, the HMD mirror full screen on it. Returns the exit status.
#pragma once

#include "session/session.h"
#include "session/session_config.h"

namespace arbci::app {

int runWorkstation(const SessionConfig& config, SessionOptions options);

}  // namespace arbci::app
