// An LSL inlet: takes one stream's samples over TCP (data protocol 110) on its own thread, and
// estimates the offset between the outlet's clock and ours with liblsl's time-correction
// exchange (UDP probes; the estimate from the probe with the shortest round trip, refreshed every
// `time_update_interval_s`).
//
// When the outlet disappears (its connection closes, or a regular stream sends nothing for
// `watchdog_s`), the inlet reports the fault and keeps looking for the stream again (same
// source_id, else same name and type, on the same host) until it returns or the inlet is
// destroyed; samples then carry the next connection number, so the reader can count the gap
// from their timestamps.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/sample_codec.h"
#include "arbci/bci/lsl/stream_info.h"

namespace arbci::bci::lsl {

struct InletStatus {
  bool connected = false;
  std::string fault;            // why it is not connected (empty while connected)
  int connections = 0;          // 1 after the first, +1 per reconnection
  bool clock_known = false;     // a time-correction estimate exists
  double clock_offset_s = 0.0;  // add to the outlet's timestamps to get ours
  double clock_rtt_s = 0.0;     // the round trip of the best probe
  std::int64_t received = 0;    // samples
  std::int64_t overflowed = 0;  // samples dropped because nobody pulled them
};

class Inlet {
 public:
  // Connects to `stream` (from resolveStreams) after fetching its full description; throws
  // LslError naming the stream when it cannot. `max_buffer_s` of samples wait to be pulled.
  Inlet(const StreamInfo& stream, LslConfig config, double max_buffer_s = 360.0,
        double watchdog_s = 3.0);
  ~Inlet();
  Inlet(const Inlet&) = delete;
  Inlet& operator=(const Inlet&) = delete;

  // The full description (channel labels), of the stream as first connected.
  const StreamInfo& info() const { return info_; }
  const SampleCodec& codec() const { return codec_; }
  // Moves up to `max` received samples into `out` (appended), oldest first; timestamps are the
  // outlet's (deduced ones filled in).
  size_t pull(std::vector<Sample>& out, size_t max = SIZE_MAX);
  InletStatus status() const;
  // Where it is connected now: "host (address:port)".
  std::string endpoint() const;

 private:
  void receiveLoop();
  void timeLoop();
  void streamOnce();  // one connection, until it breaks
  bool findAgain();   // re-resolves the stream; true when found

  StreamInfo info_;
  LslConfig config_;
  SampleCodec codec_;
  std::size_t max_samples_;
  double watchdog_s_;
  mutable std::mutex mutex_;  // everything below
  StreamInfo current_;        // the outlet connected now (uid, address, ports)
  std::deque<Sample> queue_;
  InletStatus status_;
  std::atomic<bool> stop_{false};
  std::thread receive_thread_, time_thread_;
};

}  // namespace arbci::bci::lsl
