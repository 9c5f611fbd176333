// EEG from an amplifier through Debian's eegdev library (`eeg.source: "eegdev"`): BioSemi
// ActiveTwo (`biosemi`), TOBI interface A servers (`tobiia|host|H|port|P`), or a file played as
// if it were an amplifier (`datafile|path|F.bdf`). The device string is eegdev's own
// (device|option|value|...), passed untouched as its manual asks.
//
// The device's EEG channels are read in the session's blocks, stamped on arrival like any
// amplifier's; trigger and other sensor channels are left out. A device error (a cable
// pulled, a file played to its end) is reported by fault(), named as such; the samples read
// before it are all delivered (the last block may be shorter), nothing after it.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "arbci/bci/eeg_source.h"

struct eegdev;

namespace arbci::bci {

class EegdevError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `device` is a setting (bci::eegdevSourceSchema(), bci/settings.h); the rest the session sets.
struct EegdevSourceSettings {
  EegdevSourceSettings();
  std::string device;  // e.g. "datafile|path|/data/s01.bdf"
  int block_size = kBlockSize;
  double expected_rate_hz = 0.0;  // the session's rate: a device at another rate is refused
};

class EegdevSource final : public EegSource {
 public:
  // Opens and starts the device. Throws EegdevError naming the device string and the reason
  // (unknown device, syntax, not connected, no valid rate, another rate than the session's).
  explicit EegdevSource(const EegdevSourceSettings& settings);
  ~EegdevSource() override;
  EegdevSource(const EegdevSource&) = delete;
  EegdevSource& operator=(const EegdevSource&) = delete;

  const SignalInfo& info() const override { return info_; }
  std::vector<Block> poll(int max_blocks = 64) override;
  std::string fault() const override { return fault_; }
  std::string describe() const override;

 private:
  // The first `samples` pending samples as one block (the last block at a fault may be short).
  Block takeBlock(int samples);
  EegdevSourceSettings settings_;
  struct Closer {
    void operator()(eegdev* device) const;
  };
  std::unique_ptr<eegdev, Closer> device_;
  SignalInfo info_;
  std::vector<double> scale_;  // per channel, to microvolts
  std::string device_type_;
  std::vector<float> pending_;  // sample-major samples not yet in a block
  std::int64_t next_sample_ = 0;
  std::string fault_;
};

}  // namespace arbci::bci
