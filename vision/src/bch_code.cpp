// BCH IDs: binary BCH over GF(2^6) (x^6 + x + 1), designed distance 9, shortened from 63 to 36
// bits with 12 data bits; systematic, XOR a fixed mask. A codeword is a multiple of the generator
// g(x), so the remainder of a received word modulo g(x) depends only on its error pattern; the
// remainders of all patterns of up to two errors are distinct (minimum distance 9) and are looked
// up in a table built once.
//
// Decoding runs up to a few thousand times per blurred frame (Chase trials of every reading of
// every candidate), so both steps are single table look-ups: the remainder is linear, that of the
// low 24 bits being themselves, so a word's is its low bits XOR the remainder of its high 12
// bits (4096 entries); the syndromes of the 666 correctable patterns sit in an open-addressed
// hash table, behind a 4 KB bitmap of their hashes: nearly every Chase trial is no codeword, and
// the bitmap turns it away from a few cache lines instead of the table's 48 KB (in a detector
// that a camera frame has just pushed out of the cache).
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "arbci/vision/id_codes.h"

namespace arbci::vision {
namespace {

constexpr CodeWord kGenerator = 0x1DB2777ULL;  // degree 24
constexpr int kParityBits = 24;
constexpr CodeWord kParityMask = (CodeWord{1} << kParityBits) - 1;
constexpr CodeWord kBchMask = 0x8F80B8750ULL;

// r(x) = w(x) mod g(x) for a word of up to 36 bits, by long division.
std::uint32_t remainderByDivision(CodeWord word) {
  for (int bit = 35; bit >= kParityBits; --bit) {
    if ((word >> bit) & 1U) word ^= kGenerator << (bit - kParityBits);
  }
  return static_cast<std::uint32_t>(word);
}

class DecodingTables {
 public:
  DecodingTables() {
    for (CodeWord high = 0; high < high_remainder_.size(); ++high)
      high_remainder_[high] = remainderByDivision(high << kParityBits);
    for (int i = 0; i < 36; ++i) {
      const CodeWord one = CodeWord{1} << i;
      insert(one, 1);
      for (int j = i + 1; j < 36; ++j) insert(one | CodeWord{1} << j, 2);
    }
  }

  std::uint32_t remainder(CodeWord word) const {
    return static_cast<std::uint32_t>(word & kParityMask) ^ high_remainder_[word >> kParityBits];
  }

  struct Correction {
    CodeWord error = 0;
    int bits = 0;  // 0: an empty slot
  };
  // The error pattern of at most two bits whose remainder is `syndrome` (non-zero), if any.
  const Correction* find(std::uint32_t syndrome) const {
    const std::uint32_t bit = filterBit(syndrome);
    if (((filter_[bit >> 6] >> (bit & 63)) & 1U) == 0) return nullptr;
    for (std::uint32_t slot = hash(syndrome);; slot = (slot + 1) & (kSlots - 1)) {
      const Slot& s = slots_[slot];
      if (s.correction.bits == 0) return nullptr;
      if (s.syndrome == syndrome) return &s.correction;
    }
  }

 private:
  static constexpr std::uint32_t kSlots = 2048;  // 666 patterns: a third full, ~1.2 probes
  struct Slot {
    std::uint32_t syndrome = 0;
    Correction correction;
  };
  static constexpr int kFilterBits = 15;  // 666 of 32,768 bits set: 2 % of misses get through
  static std::uint32_t hash(std::uint32_t syndrome) { return (syndrome * 0x9E3779B1U) >> 21; }
  static std::uint32_t filterBit(std::uint32_t syndrome) {
    return (syndrome * 0x9E3779B1U) >> (32 - kFilterBits);
  }
  void insert(CodeWord error, int bits) {
    const std::uint32_t syndrome = remainder(error);
    const std::uint32_t bit = filterBit(syndrome);
    filter_[bit >> 6] |= std::uint64_t{1} << (bit & 63);
    std::uint32_t slot = hash(syndrome);
    while (slots_[slot].correction.bits != 0) slot = (slot + 1) & (kSlots - 1);
    slots_[slot] = Slot{syndrome, Correction{error, bits}};
  }
  std::array<std::uint32_t, 4096> high_remainder_{};
  std::array<Slot, kSlots> slots_{};
  std::array<std::uint64_t, (1U << kFilterBits) / 64> filter_{};
};

const DecodingTables& tables() {
  static const DecodingTables built;
  return built;
}

}  // namespace

CodeWord BchCode::encode(int id) {
  const CodeWord data = static_cast<CodeWord>(id) & 0xFFF;
  const CodeWord shifted = data << kParityBits;
  return (shifted | tables().remainder(shifted)) ^ kBchMask;
}

std::optional<DecodedId> BchCode::decode(CodeWord word) {
  const DecodingTables& table = tables();
  CodeWord codeword = (word ^ kBchMask) & kCodeMask;
  const std::uint32_t syndrome = table.remainder(codeword);
  int corrected = 0;
  if (syndrome != 0) {
    const DecodingTables::Correction* correction = table.find(syndrome);
    if (!correction) return std::nullopt;
    codeword ^= correction->error;
    corrected = correction->bits;
  }
  const int id = static_cast<int>(codeword >> kParityBits);
  return DecodedId{id, corrected, 1.0f - 0.25f * static_cast<float>(corrected)};
}

int BchCode::rotationMargin(int id) {
  static const std::vector<CodeWord> codewords = [] {
    std::vector<CodeWord> words(kMaxId + 1);
    for (int i = 0; i <= kMaxId; ++i) words[i] = encode(i);
    return words;
  }();
  int margin = 36;
  const CodeGrid grid = wordToGrid(encode(id));
  for (int turns = 1; turns < 4; ++turns) {
    const CodeWord turned = gridToWord(rotateClockwise(grid, turns));
    for (CodeWord word : codewords) margin = std::min(margin, __builtin_popcountll(turned ^ word));
  }
  return margin;
}

}  // namespace arbci::vision
