// LSL's sample encoding, data protocol 110: a tag byte (1: the timestamp is deduced as the
// previous one plus 1/rate; 2: an 8-byte double timestamp follows), then the values in the
// negotiated byte order (strings each with a length of 1, 4 or 8 bytes before it). Before any
// data an outlet sends two test-pattern samples, which the client checks to prove both sides
// agree on the format.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "arbci/bci/lsl/stream_info.h"

namespace arbci::bci::lsl {

// One sample: numeric values as native bytes (channels x formatSize), or strings.
struct Sample {
  double timestamp = 0.0;
  bool deduced = false;  // the wire carried no timestamp
  std::vector<char> raw;
  std::vector<std::string> strings;
  int connection = 0;  // which of an inlet's connections delivered it (1 the first, then 2, ...)
};

class SampleCodec {
 public:
  // Throws LslError for a channel count that is not positive.
  SampleCodec(ChannelFormat format, int channels);
  ChannelFormat format() const { return format_; }
  int channels() const { return channels_; }
  size_t rawBytes() const { return static_cast<size_t>(channels_) * formatSize(format_); }

  // Appends one encoded sample; `timestamp` < 0 is sent as deduced.
  void encode(std::string& out, const Sample& sample) const;
  void encodeRaw(std::string& out, const void* values, double timestamp) const;
  // Reads one sample through `read(into, bytes)`, which must deliver exactly or throw.
  // `reverse`: the values arrive in the other byte order. Throws LslError for a malformed length.
  void decode(const std::function<void(void*, size_t)>& read, bool reverse, Sample& into) const;

  // liblsl's test pattern `offset` (4, then 2) for this format and channel count, timestamp
  // 123456.789.
  Sample testPattern(int offset) const;
  bool same(const Sample& a, const Sample& b) const;

  // Value `channel` of a numeric sample, as a double (exact for all formats but int64 beyond 2^53).
  double value(const Sample& sample, int channel) const;
  // Writes `v` (rounded for integer formats, clamped to their range) into a numeric sample.
  void setValue(Sample& sample, int channel, double v) const;

 private:
  ChannelFormat format_;
  int channels_;
};

}  // namespace arbci::bci::lsl
