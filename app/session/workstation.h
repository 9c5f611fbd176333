// The windowed workstation: the experimenter window (panels over the running session) and,
// when the session names a monitor, the HMD mirror full screen on it. Returns the exit status.
#pragma once

#include <filesystem>

#include "session/session.h"
#include "session/session_config.h"

namespace arbci::app {

// `script_file` (optional): a scripted experimenter (session/experimenter_script.h); exit status
// 4 when it fails.
int runWorkstation(const SessionConfig& config, SessionOptions options,
                   const std::filesystem::path& script_file = {});

}  // namespace arbci::app
