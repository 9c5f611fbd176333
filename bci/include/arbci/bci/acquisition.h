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

// A delivery held up (a stall of the source, the transport or this process): `samples` arrived at
// once from `first_sample` on, and/or the newest of them arrived `late_s` after the clock model
// expected it. Between `since_host_s` (the delivery before) and `host_s` (this one) the model had
// nothing new: a flash stamped in that interval rests on its extrapolation.
struct DeliveryStall {
  std::int64_t first_sample = 0;
  std::int64_t samples = 0;
  double late_s = 0.0;
  double since_host_s = 0.0, host_s = 0.0;
};

// What the clock model says of itself (see ClockModel).
struct ClockReport {
  double drift_ppm = 0.0, drift_uncertainty_ppm = 0.0, jitter_s = 0.0;
  bool drift_reliable = false, drift_at_bound = false;
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
  // Deliveries held up since the last call (only sources stamped by arrival: a source that stamps
  // its own samples, LSL, keeps true stamps through a stall).
  std::vector<DeliveryStall> takeStalls();
  // Samples a source delivered twice (a block overlapping what was already delivered): dropped.
  std::int64_t repeatedSamples() const { return repeated_.load(); }
  // A fault on the acquisition thread (the source threw): the stream stops; "" while healthy.
  std::string fault() const;

  // The clock model (thread-safe copies of what the cycle needs).
  std::int64_t firstSampleAtOrAfter(double host_s) const;
  double sampleAt(double host_s) const;
  double driftPpm() const;
  double jitterS() const;
  ClockReport clockReport() const;

  // Calls into the source from the cycle's thread (stimuli, attention, the screen).
  void withSource(const std::function<void(EegSource&)>& call);

 private:
  void pump();
  ClockModel::Observation deliver(const Block& block, double host_s);
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
  std::vector<DeliveryStall> stalls_;
  double last_delivery_host_ = 0.0;
  std::string fault_;
  ClockModel model_;
  std::int64_t first_sample_ = 0;  // of the stream
  std::int64_t next_sample_ = -1;  // after the newest block delivered (-1: none yet)
  std::atomic<std::int64_t> lost_{0};
  std::atomic<std::int64_t> repeated_{0};
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace arbci::bci
