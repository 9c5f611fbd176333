// The signal the LSL tests send between processes: every value a function of the sample index
// and channel, so the receiver can check each one bit for bit. Channels 0 and 1 carry the index
// itself (low and high 16 bits), the others a hash of it, all exact in float32.
#pragma once

#include <cstdint>

namespace arbci::test {

inline float lslTestValue(std::int64_t sample, int channel) {
  if (channel == 0) return static_cast<float>(sample & 0xffff);
  if (channel == 1) return static_cast<float>(sample >> 16);
  std::uint32_t h = static_cast<std::uint32_t>(sample) * 2654435761u ^
                    (static_cast<std::uint32_t>(channel) * 40503u + 0x9e3779b9u);
  h ^= h >> 15;
  h *= 0x2c1b3c6du;
  h ^= h >> 12;
  return static_cast<float>(static_cast<std::int32_t>(h % 400001u) - 200000) / 16.0f;
}

}  // namespace arbci::test
