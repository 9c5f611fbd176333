// ARToolKitPlus-compatible ID marker codes: the 6x6 code grid as a 36-bit word, simple IDs
// (0..511, 4-fold repetition) and BCH IDs (0..4095, BCH(36,12) with 2-error correction).
// Bit k of a word (k = 0 is the least significant bit) is grid cell p = 35 - k, p = 6 * row + col,
// so the top-left cell is the most significant bit; a set bit is a white cell.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

namespace arbci::vision {

using CodeWord = std::uint64_t;  // the low 36 bits are used
constexpr int kCodeCells = 6;
constexpr CodeWord kCodeMask = (CodeWord{1} << 36) - 1;

// A 6x6 grid of cells, row-major, true = white.
using CodeGrid = std::array<bool, 36>;

CodeGrid wordToGrid(CodeWord word);
CodeWord gridToWord(const CodeGrid& grid);
// The grid turned 90 degrees clockwise, `turns` times.
CodeGrid rotateClockwise(const CodeGrid& grid, int turns);

struct DecodedId {
  int id = -1;
  int corrected_bits = 0;   // bit errors corrected
  float confidence = 0.0f;  // ARToolKitPlus's confidence for this decode
};

class SimpleIdCode {
 public:
  static constexpr int kMaxId = 511;
  static CodeWord encode(int id);
  // Majority vote over the four copies; nullopt when ARToolKitPlus would reject the word
  // (confidence below 0.9: more than one 3:1 vote, or any 2:2 tie).
  static std::optional<DecodedId> decode(CodeWord word);
};

class BchCode {
 public:
  static constexpr int kMaxId = 4095;
  static constexpr int kMaxCorrectedBits = 2;  // ARToolKitPlus drops decodes with confidence < 0.5
  static CodeWord encode(int id);
  // Syndrome decoding; nullopt when more than two bits are wrong (the word is not within
  // distance 2 of a codeword).
  static std::optional<DecodedId> decode(CodeWord word);
  // The fewest bits by which a quarter, half or three-quarter turn of `id`'s marker differs from
  // any codeword. Below 5, a few misread cells can decode the turned marker as another id
  // (ARToolKitPlus's notes list 1550/3080, 2098/2492, 2522/3192 among 60 such ids).
  static int rotationMargin(int id);
};

}  // namespace arbci::vision
