// The windowed workstation: the experimenter window (panels over the running session) and,
// when the session names a monitor, the HMD mirror full screen on it. Returns the exit status.
#pragma once

#include <filesystem>
#include <functional>

#include "arbci/session/session.h"

namespace arbci::app {

struct WorkstationOptions {
  // A scripted experimenter (workstation/experimenter_script.h); exit status 4 when it fails.
  std::filesystem::path script;
  bool wait_for_start = true;     // the experimenter presses Start (else it runs at once)
  bool close_when_ended = false;  // the window closes once the session has ended
  // Nobody at the window (the timing check): the session starts itself and a failed pre-flight
  // ends it, as headless.
  bool unattended = false;
  // Where the run is exported when it ends (arbci run --bids): the start screen shows the run it
  // will take.
  std::filesystem::path bids_root;
  // Called once the session is open (its folder in use): a failure before that leaves nothing.
  std::function<void()> opened;
};

int runWorkstation(const session::SessionConfig& config, session::SessionOptions options,
                   const WorkstationOptions& workstation = {});

}  // namespace arbci::app
