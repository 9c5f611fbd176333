// The timing check: how far the recorded flash onsets ("Stim" events, stamped at presentation on
// the EEG clock) lie from what a photodiode on the display saw (the rising edges of its channel).
// Each onset is paired with the nearest rising edge within half an SOA; what stays unpaired is
// counted, never dropped silently.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arbci/bci/recording.h"

namespace arbci::bci {

struct PhotodiodeReport {
  std::string channel;
  double rate_hz = 0.0;
  double threshold = 0.0;  // half-way between the channel's low and high levels
  int flashes = 0;         // Stim events in the recording
  int edges = 0;           // rising edges of the photodiode
  int count = 0;           // pairs
  int unmatched_flashes = 0, unmatched_edges = 0;
  std::vector<double> offsets_ms;  // edge minus onset, per pair (positive: the diode saw it later)
  std::vector<std::int64_t> paired_onsets;     // each pair's onset sample (as offsets_ms)
  std::vector<std::int64_t> unmatched_onsets;  // the onsets no edge was near
  double mean_ms = 0.0, sd_ms = 0.0, min_ms = 0.0, max_ms = 0.0;
};

// Throws std::invalid_argument naming the channel when the recording has no such channel, or
// when it never changes (no diode attached, or a patch that never lit).
PhotodiodeReport checkPhotodiode(const Recording& recording, const std::string& channel,
                                 double max_offset_s);

// The same check where the diode feeds a trigger input and the amplifier records a marker
// (`marker`, an annotation's whole text, "Stimulus/S  1") at each edge. Throws
// std::invalid_argument naming the marker when the recording has none of it.
PhotodiodeReport checkPhotodiodeMarkers(const Recording& recording, const std::string& marker,
                                        double max_offset_s);

}  // namespace arbci::bci
