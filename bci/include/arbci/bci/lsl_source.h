// EEG from a Lab Streaming Layer stream (an amplifier's LSL app, or `arbci eeg stream`): the
// stream found by name and/or type, its samples cut into the session's blocks, each block
// stamped with the time its last sample was taken (the outlet's timestamp moved onto our clock by
// LSL's time correction), which is what the acquisition's clock model fits.
//
// Values are taken as microvolts unless the stream's channel unit says volts or millivolts. A
// stream that disappears is reported by fault() and reconnected when it returns; the samples it
// missed, counted from the timestamps on either side, appear as a gap in the sample numbers,
// which the acquisition fills with zeros and counts as lost.
#pragma once

#include <deque>
#include <memory>
#include <string>

#include "arbci/bci/eeg_source.h"
#include "arbci/bci/lsl/config.h"

namespace arbci::bci {

namespace lsl {
class Inlet;
}

// name, type, source_id, host and resolve_timeout_s are settings (bci::lslSourceSchema(),
// bci/settings.h, takes their defaults); the rest the session sets from its EEG settings.
struct LslSourceSettings {
  LslSourceSettings();
  std::string name;  // the stream's name (empty: any)
  std::string type;
  std::string source_id;  // the stream's source id (empty: any): tells same-named streams apart
  std::string host;       // the host it streams from (empty: any)
  double resolve_timeout_s;
  int block_size = kBlockSize;
  double expected_rate_hz = 0.0;  // the session's rate: a stream at another rate is refused
  // Refuse a stream that answers but sends no sample within resolve_timeout_s (pre-flight).
  bool require_samples = true;
  lsl::LslConfig config;
};

class LslSource final : public EegSource {
 public:
  // Finds and connects to the stream. Throws lsl::LslError with a message naming the stream
  // and the scope when none answers, when several match, or when its rate or format cannot be
  // used.
  explicit LslSource(const LslSourceSettings& settings);
  ~LslSource() override;

  const SignalInfo& info() const override { return info_; }
  std::vector<Block> poll(int max_blocks = 64) override;
  std::string fault() const override;
  std::string describe() const override;
  // From the stream's metadata (<desc><channels><channel><impedance>), as connected.
  std::string impedance() const override { return impedance_; }
  // Once, at the first sample: the channels whose stated unit is not a voltage (their values
  // kept as they are), for the recording.
  std::vector<Annotation> takeAnnotations() override;
  // Samples the stream missed while its outlet was away (as counted from the timestamps).
  std::int64_t gapSamples() const { return gap_samples_; }

 private:
  void flush(std::vector<Block>& out);

  LslSourceSettings settings_;
  std::unique_ptr<lsl::Inlet> inlet_;
  SignalInfo info_;
  std::vector<double> scale_;  // per channel, to microvolts
  std::string name_, host_, impedance_;
  std::string unit_note_;  // bci::nonVoltageNote of the stream's channels
  bool unit_note_taken_ = false;
  Block pending_;
  std::int64_t next_index_ = 0;
  int connection_ = 0;
  double last_timestamp_ = 0.0;
  std::int64_t gap_samples_ = 0;
  std::deque<std::pair<std::int64_t, double>> rate_history_;  // (sample, outlet timestamp)
};

}  // namespace arbci::bci
