#include "arbci/bci/lsl/sample_codec.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "arbci/bci/lsl/config.h"

namespace arbci::bci::lsl {
namespace {

constexpr std::uint8_t kDeducedTag = 1;
constexpr std::uint8_t kTransmittedTag = 2;

void reverseEach(char* data, size_t count, int width) {
  if (width <= 1) return;
  for (size_t i = 0; i < count; ++i) std::reverse(data + i * width, data + (i + 1) * width);
}

template <typename T>
void fillPattern(char* raw, int channels, long long offset) {
  for (int k = 0; k < channels; ++k) {
    unsigned long long v =
        static_cast<unsigned long long>(k) + static_cast<unsigned long long>(offset);
    if (std::is_integral_v<T>) v %= static_cast<unsigned long long>(std::numeric_limits<T>::max());
    const T value = (k % 2 == 0) ? static_cast<T>(v) : static_cast<T>(-static_cast<T>(v));
    std::memcpy(raw + static_cast<size_t>(k) * sizeof(T), &value, sizeof(T));
  }
}

template <typename T>
T load(const char* raw, int channel) {
  T v;
  std::memcpy(&v, raw + static_cast<size_t>(channel) * sizeof(T), sizeof(T));
  return v;
}

template <typename T>
void storeRounded(char* raw, int channel, double v) {
  if constexpr (std::is_integral_v<T>) {
    v = std::clamp(std::round(v), static_cast<double>(std::numeric_limits<T>::min()),
                   static_cast<double>(std::numeric_limits<T>::max()));
  }
  const T value = static_cast<T>(v);
  std::memcpy(raw + static_cast<size_t>(channel) * sizeof(T), &value, sizeof(T));
}

}  // namespace

SampleCodec::SampleCodec(ChannelFormat format, int channels)
    : format_(format), channels_(channels) {
  if (channels <= 0) throw LslError("an LSL stream needs at least one channel");
}

void SampleCodec::encodeRaw(std::string& out, const void* values, double timestamp) const {
  if (timestamp < 0) {
    out += static_cast<char>(kDeducedTag);
  } else {
    out += static_cast<char>(kTransmittedTag);
    out.append(reinterpret_cast<const char*>(&timestamp), sizeof timestamp);
  }
  out.append(static_cast<const char*>(values), rawBytes());
}

void SampleCodec::encode(std::string& out, const Sample& sample) const {
  if (format_ != ChannelFormat::String) {
    if (sample.raw.size() != rawBytes())
      throw LslError("a sample of the wrong size for its stream");
    encodeRaw(out, sample.raw.data(), sample.deduced ? -1.0 : sample.timestamp);
    return;
  }
  if (static_cast<int>(sample.strings.size()) != channels_)
    throw LslError("a string sample with the wrong number of channels");
  if (sample.deduced) {
    out += static_cast<char>(kDeducedTag);
  } else {
    out += static_cast<char>(kTransmittedTag);
    out.append(reinterpret_cast<const char*>(&sample.timestamp), sizeof sample.timestamp);
  }
  for (const auto& s : sample.strings) {
    if (s.size() <= 0xFF) {
      out += static_cast<char>(1);
      out += static_cast<char>(s.size());
    } else {
      const std::uint32_t length = static_cast<std::uint32_t>(s.size());
      out += static_cast<char>(4);
      out.append(reinterpret_cast<const char*>(&length), sizeof length);
    }
    out += s;
  }
}

void SampleCodec::decode(const std::function<void(void*, size_t)>& read, bool reverse,
                         Sample& into) const {
  std::uint8_t tag = 0;
  read(&tag, 1);
  if (tag == kDeducedTag) {
    into.deduced = true;
  } else if (tag == kTransmittedTag) {
    into.deduced = false;
    read(&into.timestamp, sizeof into.timestamp);
    if (reverse) reverseEach(reinterpret_cast<char*>(&into.timestamp), 1, 8);
  } else {
    throw LslError("corrupt LSL data: sample tag " + std::to_string(tag) + " (expected 1 or 2)");
  }
  if (format_ != ChannelFormat::String) {
    into.raw.resize(rawBytes());
    read(into.raw.data(), into.raw.size());
    if (reverse) reverseEach(into.raw.data(), static_cast<size_t>(channels_), formatSize(format_));
    return;
  }
  into.strings.resize(static_cast<size_t>(channels_));
  for (auto& s : into.strings) {
    std::uint8_t width = 0;
    read(&width, 1);
    std::uint64_t length = 0;
    if (width == 1) {
      std::uint8_t l = 0;
      read(&l, 1);
      length = l;
    } else if (width == 2 || width == 4 || width == 8) {
      char bytes[8] = {};
      read(bytes, width);
      if (reverse) std::reverse(bytes, bytes + width);
      if (width == 2) length = load<std::uint16_t>(bytes, 0);
      if (width == 4) length = load<std::uint32_t>(bytes, 0);
      if (width == 8) length = load<std::uint64_t>(bytes, 0);
    } else {
      throw LslError("corrupt LSL data: string length of " + std::to_string(width) + " bytes");
    }
    if (length > (1u << 24))
      throw LslError("corrupt LSL data: a string of " + std::to_string(length) + " bytes");
    s.resize(static_cast<size_t>(length));
    if (length > 0) read(s.data(), s.size());
  }
}

Sample SampleCodec::testPattern(int offset) const {
  Sample s;
  s.timestamp = 123456.789;
  s.raw.assign(rawBytes(), 0);
  switch (format_) {
    case ChannelFormat::Float32:
      fillPattern<float>(s.raw.data(), channels_, offset);
      break;
    case ChannelFormat::Double64:
      fillPattern<double>(s.raw.data(), channels_, offset + 16777217LL);
      break;
    case ChannelFormat::Int32:
      fillPattern<std::int32_t>(s.raw.data(), channels_, offset + 65537LL);
      break;
    case ChannelFormat::Int16:
      fillPattern<std::int16_t>(s.raw.data(), channels_, offset + 257LL);
      break;
    case ChannelFormat::Int8:
      fillPattern<std::int8_t>(s.raw.data(), channels_, offset + 1LL);
      break;
    case ChannelFormat::Int64:
      for (int k = 0; k < channels_; ++k) {
        std::int64_t v = k + 2147483649LL + offset;
        if (k % 2 == 1) v = -v;
        std::memcpy(s.raw.data() + static_cast<size_t>(k) * 8, &v, 8);
      }
      break;
    case ChannelFormat::String:
      s.raw.clear();
      for (int k = 0; k < channels_; ++k)
        s.strings.push_back(std::to_string((k + 10) * (k % 2 == 0 ? 1 : -1)));
      break;
  }
  return s;
}

bool SampleCodec::same(const Sample& a, const Sample& b) const {
  return a.timestamp == b.timestamp && a.raw == b.raw && a.strings == b.strings;
}

double SampleCodec::value(const Sample& sample, int channel) const {
  const char* raw = sample.raw.data();
  switch (format_) {
    case ChannelFormat::Float32:
      return load<float>(raw, channel);
    case ChannelFormat::Double64:
      return load<double>(raw, channel);
    case ChannelFormat::Int32:
      return load<std::int32_t>(raw, channel);
    case ChannelFormat::Int16:
      return load<std::int16_t>(raw, channel);
    case ChannelFormat::Int8:
      return load<std::int8_t>(raw, channel);
    case ChannelFormat::Int64:
      return static_cast<double>(load<std::int64_t>(raw, channel));
    case ChannelFormat::String:
      break;
  }
  throw LslError("a string stream has no numeric values");
}

void SampleCodec::setValue(Sample& sample, int channel, double v) const {
  sample.raw.resize(rawBytes());
  char* raw = sample.raw.data();
  switch (format_) {
    case ChannelFormat::Float32:
      storeRounded<float>(raw, channel, v);
      return;
    case ChannelFormat::Double64:
      storeRounded<double>(raw, channel, v);
      return;
    case ChannelFormat::Int32:
      storeRounded<std::int32_t>(raw, channel, v);
      return;
    case ChannelFormat::Int16:
      storeRounded<std::int16_t>(raw, channel, v);
      return;
    case ChannelFormat::Int8:
      storeRounded<std::int8_t>(raw, channel, v);
      return;
    case ChannelFormat::Int64:
      storeRounded<std::int64_t>(raw, channel, v);
      return;
    case ChannelFormat::String:
      break;
  }
  throw LslError("a string stream has no numeric values");
}

}  // namespace arbci::bci::lsl
