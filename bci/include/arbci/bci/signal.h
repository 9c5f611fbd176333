// EEG in blocks: channels x samples of microvolts, stamped with the index of the first sample.
// The sample index is the experiment's clock; stimulus events carry the index of the sample at
// which they were presented.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace arbci::bci {

// What a signal is (set by whoever has one: a reader, a source): no default rate or block.
struct SignalInfo {
  double rate_hz = 0.0;
  std::vector<std::string> channels;
  int block_size = 0;  // samples per block (15 at 256 Hz: one 58.6 ms cycle)
  int channelCount() const { return static_cast<int>(channels.size()); }
  double blockSeconds() const { return block_size / rate_hz; }
};

// Channel-major: sample s of channel c is data[c * samples + s].
// Samples a block holds unless a source or the session says otherwise: 15 at 256 Hz is one 58.6 ms
// cycle (the session's eeg.block_size, whose default this is).
inline constexpr int kBlockSize = 15;

struct Block {
  std::int64_t first_sample = 0;
  int channels = 0;
  int samples = 0;
  std::vector<float> data;
  // When the source knows it (an LSL stream's time-corrected stamps): the host instant its last
  // sample was taken; NaN otherwise (the acquisition then uses the block's arrival).
  double taken_host_s = std::numeric_limits<double>::quiet_NaN();

  Block() = default;
  Block(std::int64_t first, int channel_count, int sample_count)
      : first_sample(first),
        channels(channel_count),
        samples(sample_count),
        data(static_cast<size_t>(channel_count) * sample_count, 0.0f) {}
  float& at(int channel, int sample) {
    return data[static_cast<size_t>(channel) * samples + sample];
  }
  float at(int channel, int sample) const {
    return data[static_cast<size_t>(channel) * samples + sample];
  }
  std::int64_t endSample() const { return first_sample + samples; }
};

// Channel-major samples without one channel (a photodiode kept out of the EEG): blocks and whole
// recordings alike.
inline std::vector<float> withoutChannel(const std::vector<float>& data, int channels,
                                         std::int64_t samples, int drop) {
  std::vector<float> out;
  out.reserve(data.size() - static_cast<size_t>(samples));
  for (int c = 0; c < channels; ++c) {
    if (c == drop) continue;
    const auto begin = data.begin() + static_cast<std::ptrdiff_t>(c * samples);
    out.insert(out.end(), begin, begin + static_cast<std::ptrdiff_t>(samples));
  }
  return out;
}

// A stimulus presented to the subject (or any other event of the session).
struct StimulusEvent {
  std::int64_t sample = 0;  // the EEG sample at which it was presented
  int code = 0;             // which stimulus: an object, a row or a column (1-based)
  bool target = false;      // the stimulus the subject attends
  int duration_samples = 0;
  // False when nobody knows whether it was attended (a free choice): recorded as "U", and left
  // out of training.
  bool known = true;
};

// Other events a session records: phase changes, selections, robot commands.
struct Annotation {
  std::int64_t sample = 0;
  std::string text;
  int duration_samples = 0;
};

}  // namespace arbci::bci
