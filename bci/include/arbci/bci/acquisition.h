// EEG acquisition: the source delivers blocks on its own clock into a ring buffer (the last
// `queue_s` of signal), each block's first sample index and the host time it arrived feeding a
// clock model that learns the mapping from host time to samples. The cycle takes what has
// arrived; it never paces the source.
//
// Live (a real or real-time source): a thread polls the source every millisecond and stamps each
// block with hostSeconds(). Stepped (a headless simulated run): the cycle advances the simulated
// clock and the blocks due by then are taken at once, each stamped the instant it became
// available, so the same inputs give the same samples and stamps, run after run.
//
// Nothing is dropped silently: a gap in the source's sample numbers is filled with zeros and
// counted as lost, and so is what the ring overwrote before the cycle took it (a cycle that fell
// more than `queue_s` behind).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/clock_model.h"
#include "arbci/bci/eeg_source.h"
#include "arbci/bci/ring_buffer.h"
#include "arbci/bci/sample_clock.h"

namespace arbci::bci {

struct AcquisitionSettings {
  double queue_s = 10.0;        // how much signal waits for the cycle before the oldest is lost
  double latency_s = 0.0;       // delivery latency to subtract (measured by timing-check)
  double clock_window_s = 120;  // history of the clock model's fit
};

// A gap or overflow: `samples` lost from `first_sample` on (filled with zeros in the stream).
struct SampleLoss {
  std::int64_t first_sample = 0;
  std::int64_t samples = 0;
  std::string reason;
};

class Acquisition {
 public:
  enum class Mode { Live, Stepped };
  // `clock` is the clock that paces `source` (a ManualClock for Stepped). Throws
  // std::invalid_argument when a stepped acquisition has no manual clock.
  Acquisition(std::unique_ptr<EegSource> source, std::shared_ptr<SampleClock> clock, Mode mode,
              const AcquisitionSettings& settings = {});
  ~Acquisition();  // stops the thread
  Acquisition(const Acquisition&) = delete;
  Acquisition& operator=(const Acquisition&) = delete;

  const SignalInfo& info() const { return info_; }
  Mode mode() const { return mode_; }
  void start();  // Live: starts the thread (idempotent)
  void stop();

  // Stepped: the simulated clock is now at `host_s`; takes the blocks due.
  void advanceTo(double host_s);

  // The signal that arrived since the last call, in order and without gaps (lost stretches as
  // zeros). Call from one thread (the cycle's).
  std::vector<Block> take();
  std::vector<SampleLoss> takeLosses();
  std::int64_t lostSamples() const { return lost_.load(); }

  // The clock model (thread-safe copies of what the cycle needs).
  std::int64_t firstSampleAtOrAfter(double host_s) const;
  double sampleAt(double host_s) const;
  double driftPpm() const;
  double jitterS() const;

  // Calls into the source from the cycle's thread (stimuli, attention, the screen).
  void withSource(const std::function<void(EegSource&)>& call);

 private:
  void pump();
  void deliver(const Block& block, double host_s);
  void loop();

  std::unique_ptr<EegSource> source_;
  std::shared_ptr<SampleClock> clock_;
  Mode mode_;
  AcquisitionSettings settings_;
  SignalInfo info_;
  mutable std::mutex source_mutex_;  // the source, and the pump
  mutable std::mutex state_mutex_;   // losses, the clock model, where the stream starts
  RingBuffer ring_;
  std::optional<RingBuffer::Reader> reader_;  // the cycle's; from the stream's first sample
  std::vector<SampleLoss> losses_;
  ClockModel model_;
  std::int64_t first_sample_ = 0;  // of the stream
  std::int64_t next_sample_ = -1;  // after the newest block delivered (-1: none yet)
  std::atomic<std::int64_t> lost_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace arbci::bci
