// Cuts epochs around stimulus events from a (filtered) stream, each as soon as its last sample
// has arrived. An event that arrives after its window has left the history is counted as missed,
// never dropped silently.
#pragma once

#include <cstdint>
#include <vector>

#include "arbci/bci/signal.h"

namespace arbci::bci {

// The window is a setting (the classifier's window_ms, bci/settings.h): no default here.
struct EpochWindow {
  double start_s = 0.0;  // relative to the stimulus onset
  double end_s = 0.0;
};

struct Epoch {
  StimulusEvent event;
  int channels = 0;
  int samples = 0;
  std::vector<float> data;  // channel-major
  float at(int channel, int sample) const {
    return data[static_cast<size_t>(channel) * samples + sample];
  }
};

class Epocher {
 public:
  // `history_s`: how long samples are kept for events that arrive late.
  Epocher(int channels, double rate_hz, const EpochWindow& window, double history_s = 5.0);

  void addEvent(const StimulusEvent& event);
  // Appends a block (blocks must follow each other) and returns the epochs it completed, in
  // order of onset.
  std::vector<Epoch> push(const Block& block);
  // Epochs whose samples are all available now (for events added after their samples arrived).
  std::vector<Epoch> completed();

  int samplesPerEpoch() const { return length_; }
  int offsetSamples() const { return offset_; }
  std::int64_t missed() const { return missed_; }
  size_t pending() const { return events_.size(); }

 private:
  int channels_;
  int offset_, length_;
  int history_;
  std::vector<float> buffer_;  // channel-major ring of `history_` samples
  std::int64_t end_ = -1;      // index after the newest sample
  std::int64_t start_ = 0;     // first sample ever pushed
  std::vector<StimulusEvent> events_;
  std::int64_t missed_ = 0;
};

}  // namespace arbci::bci
