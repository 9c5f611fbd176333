// Channels that carry no usable EEG: flat (a loose or shorted electrode: almost no variation) or
// drifting (a failing contact: a standard deviation far above the others', as bi2012's F8 and C4
// drifting by ~1e5 uV). Detected on the raw signal of each recording, reported, and removed on
// request before anything is filtered (a drifting channel would spoil a common average).
#pragma once

#include <string>
#include <vector>

#include "arbci/bci/recording.h"

namespace arbci::bci {

// A standard deviation below this is a flat channel, offline and live (signal_quality.h).
inline constexpr double kFlatSdUv = 0.5;

struct ChannelQuality {
  std::string channel;
  double sd_uv = 0.0;     // of the raw signal
  bool flat = false;      // sd below 0.5 uV
  bool drifting = false;  // sd over 20 times the median channel's
  bool bad() const { return flat || drifting; }
};

// The EEG channels of `recording` (not a session's photodiode channel).
std::vector<ChannelQuality> assessChannels(const Recording& recording);
// The recording without `channels` (by name; names it lacks are ignored).
Recording withoutChannels(const Recording& recording, const std::vector<std::string>& channels);

}  // namespace arbci::bci
