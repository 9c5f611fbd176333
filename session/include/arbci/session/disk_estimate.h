// How much disk a planned run writes: the recording, the log and the HMD screenshots, from the
// session's settings, for the pre-flight's free-space check. An estimate with room to spare: a
// run that fills the disk ends as a fault (the recording's writes are checked), so the check
// only has to catch the run that cannot fit.
#pragma once

#include <cstdint>
#include <string>

#include "arbci/session/session_config.h"

namespace arbci::session {

struct DiskEstimate {
  std::uintmax_t bytes = 0;  // twice the planned run's files (retakes, pauses, a longer day)
  double planned_s = 0.0;    // the planned run without pauses
  std::string what;          // "about 85 MB: ..." for the failure message
};

DiskEstimate plannedRunBytes(const SessionConfig& config, int eeg_channels, double eeg_rate_hz);

}  // namespace arbci::session
