// BCH IDs: binary BCH over GF(2^6) (x^6 + x + 1), designed distance 9, shortened from 63 to 36
// bits with 12 data bits; systematic, XOR a fixed mask. A codeword is a multiple of the generator
// g(x), so the remainder of a received word modulo g(x) depends only on its error pattern; the
// remainders of all patterns of up to two errors are distinct (minimum distance 9) and are looked
// up in a table built once.
#include <algorithm>
#include <utility>
#include <vector>

#include "arbci/vision/id_codes.h"

namespace arbci::vision {
namespace {

constexpr CodeWord kGenerator = 0x1DB2777ULL;  // degree 24
constexpr int kParityBits = 24;
constexpr CodeWord kBchMask = 0x8F80B8750ULL;

// r(x) = w(x) mod g(x) for a word of up to 36 bits.
std::uint32_t remainder(CodeWord word) {
  for (int bit = 35; bit >= kParityBits; --bit) {
    if ((word >> bit) & 1U) word ^= kGenerator << (bit - kParityBits);
  }
  return static_cast<std::uint32_t>(word);
}

struct SyndromeTable {
  std::vector<std::pair<std::uint32_t, CodeWord>> entries;  // sorted by syndrome

  SyndromeTable() {
    for (int i = 0; i < 36; ++i) {
      const CodeWord one = CodeWord{1} << i;
      entries.emplace_back(remainder(one), one);
      for (int j = i + 1; j < 36; ++j) {
        const CodeWord two = one | CodeWord{1} << j;
        entries.emplace_back(remainder(two), two);
      }
    }
    std::sort(entries.begin(), entries.end());
  }

  const CodeWord* find(std::uint32_t syndrome) const {
    auto found =
        std::lower_bound(entries.begin(), entries.end(), std::make_pair(syndrome, CodeWord{0}));
    return found != entries.end() && found->first == syndrome ? &found->second : nullptr;
  }
};

const SyndromeTable& syndromeTable() {
  static const SyndromeTable table;
  return table;
}

}  // namespace

CodeWord BchCode::encode(int id) {
  const CodeWord data = static_cast<CodeWord>(id) & 0xFFF;
  const CodeWord shifted = data << kParityBits;
  return (shifted | remainder(shifted)) ^ kBchMask;
}

std::optional<DecodedId> BchCode::decode(CodeWord word) {
  CodeWord codeword = (word ^ kBchMask) & kCodeMask;
  const std::uint32_t syndrome = remainder(codeword);
  int corrected = 0;
  if (syndrome != 0) {
    const CodeWord* error = syndromeTable().find(syndrome);
    if (!error) return std::nullopt;
    codeword ^= *error;
    corrected = __builtin_popcountll(*error);
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
