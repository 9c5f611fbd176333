// The last N samples of every channel, for several readers at their own pace. A reader that falls
// more than the capacity behind is told how many samples it lost (and continues with the oldest
// kept); nothing is dropped silently. Writers and readers may be on different threads.
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "arbci/bci/signal.h"

namespace arbci::bci {

class RingBuffer {
 public:
  RingBuffer(int channels, int capacity_samples);

  // Appends a block; throws std::invalid_argument if it does not continue the last one (a gap or
  // overlap in the sample clock) or has another channel count.
  void write(const Block& block);
  std::int64_t end() const;  // the index after the newest sample

  struct Read {
    Block block;            // the samples read (possibly none)
    std::int64_t lost = 0;  // samples overwritten before this reader reached them
  };

  class Reader {
   public:
    // Up to `max_samples` samples from where this reader stands.
    Read read(int max_samples);
    std::int64_t position() const { return position_; }

   private:
    friend class RingBuffer;
    Reader(RingBuffer& buffer, std::int64_t position) : buffer_(&buffer), position_(position) {}
    RingBuffer* buffer_;
    std::int64_t position_;
  };

  // A reader starting at `from` (by default the next sample to be written).
  Reader reader(std::int64_t from = -1);

 private:
  int channels_;
  int capacity_;
  std::vector<float> data_;  // channel-major rings
  std::int64_t end_ = -1;    // -1 until the first write
  std::int64_t start_ = 0;   // index of the first sample ever written
  mutable std::mutex mutex_;
};

}  // namespace arbci::bci
