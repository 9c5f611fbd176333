// Replays a recording (any format readRecording reads) as a source: in blocks, paced by a clock
// (WallClock for real time, UnboundedClock for as fast as it is read), with its recorded stimuli.
#pragma once

#include <memory>

#include "arbci/bci/eeg_source.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/sample_clock.h"

namespace arbci::bci {

class FileSource final : public EegSource {
 public:
  // `block_size` 0 keeps the recording's own block size.
  FileSource(Recording recording, std::shared_ptr<const SampleClock> clock, int block_size = 0);

  const SignalInfo& info() const override { return recording_.info; }
  std::vector<Block> poll(int max_blocks = 64) override;
  bool finished() const override { return delivered_ >= recording_.samples; }
  std::vector<StimulusEvent> takeRecordedStimuli() override;
  // "the file F (8 channels at 256 Hz, 45.0 s)".
  std::string describe() const override;
  const Recording& recording() const { return recording_; }

 private:
  Recording recording_;
  std::shared_ptr<const SampleClock> clock_;
  std::int64_t delivered_ = 0;
  size_t next_stimulus_ = 0;
};

}  // namespace arbci::bci
