#include "code_decoder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <span>

#include "arbci/vision/id_codes.h"

namespace arbci::vision {
namespace {

// Where each cell of the sampled grid lands after `turns` clockwise quarter turns (the cell at
// (r, c) moves to (c, 5 - r) per turn), as a bit of the turned grid's word.
struct Rotations {
  std::array<std::array<CodeWord, 36>, 4> bit_of_cell{};
  std::array<std::array<int, 36>, 4> cell_of_bit{};  // bit k of the turned word: the sampled cell
  Rotations() {
    for (int p = 0; p < 36; ++p) {
      int cell = p;
      for (int turns = 0; turns < 4; ++turns) {
        bit_of_cell[turns][p] = CodeWord{1} << (35 - cell);
        cell_of_bit[turns][35 - cell] = p;
        cell = (cell % 6) * 6 + (5 - cell / 6);
      }
    }
  }
  CodeWord turned(const CodeGrid& grid, int turns) const {
    CodeWord word = 0;
    for (int p = 0; p < 36; ++p) word |= grid[p] ? bit_of_cell[turns][p] : 0;
    return word;
  }
};

const Rotations& rotations() {
  static const Rotations table;
  return table;
}

// ARToolKitPlus's rule: the rotation with the fewest corrected bits; a tie is ambiguous.
std::optional<CodeDecode> hardDecode(const IdCode& code, const CodeGrid& sampled, bool& ambiguous) {
  std::optional<CodeDecode> best;
  ambiguous = false;
  for (int turns = 0; turns < 4; ++turns) {
    const auto decoded = code.decode(rotations().turned(sampled, turns));
    if (!decoded) continue;
    if (!best || decoded->corrected_bits < best->corrected_bits) {
      best = CodeDecode{decoded->id, turns, decoded->corrected_bits, decoded->confidence};
      ambiguous = false;
    } else if (decoded->corrected_bits == best->corrected_bits) {
      ambiguous = true;
    }
  }
  return best;
}

// Chase decoding of a BCH word (see the header). Accepts a codeword that disagrees with at most
// kMaxDisagreements cells whose summed reliability is at most kMaxWeight, and that beats every
// other candidate (another id or orientation) by kMinMargin. Trials are built in each turned
// word directly (the flipped cells' bits), not as turned grids: up to 64 trials x 4 turns.
// `nearest`: how many cells at least any codeword (in any turn) disagrees with.
std::optional<CodeDecode> chaseDecode(const IdCode& code, const CodeGrid& sampled,
                                      const std::array<float, 36>& reliability, int nearest) {
  constexpr int kFlipped = 6;
  constexpr float kMaxReliabilityToFlip = 0.5f, kMaxWeight = 1.2f, kMinMargin = 0.6f;
  constexpr int kMaxDisagreements = 5;
  std::array<int, 36> order;
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + kFlipped, order.end(),
                    [&](int a, int b) { return reliability[a] < reliability[b]; });
  // Every codeword disagrees with at least `nearest` cells, weighing at least the least reliable
  // ones: when even they weigh too much, no trial can be accepted (a clearly read decoy).
  float least_weight = 0.0f;
  for (int k = 0; k < std::min(nearest, kFlipped); ++k) least_weight += reliability[order[k]];
  if (least_weight > kMaxWeight) return std::nullopt;
  int flippable = 0;
  while (flippable < kFlipped && reliability[order[flippable]] < kMaxReliabilityToFlip) ++flippable;

  struct Candidate {
    int id, turns, disagreements;
    float weight;
  };
  Candidate best{-1, 0, 0, 1e9f}, second{-1, 0, 0, 1e9f};
  const Rotations& rotation = rotations();
  for (int turns = 0; turns < 4; ++turns) {
    const CodeWord received = rotation.turned(sampled, turns);
    std::array<CodeWord, kFlipped> flip{};
    for (int b = 0; b < flippable; ++b) flip[b] = rotation.bit_of_cell[turns][order[b]];
    // The patterns in Gray-code order, each one cell away from the last (the outcome does not
    // depend on the order: only the two lightest candidates count, and a tie between them
    // refuses).
    CodeWord trial = received;
    for (int step = 0; step < (1 << flippable); ++step) {
      if (step > 0) trial ^= flip[__builtin_ctz(static_cast<unsigned>(step))];
      const auto decoded = code.decode(trial);
      if (!decoded) continue;
      if (decoded->id == best.id && turns == best.turns) continue;
      if (decoded->id == second.id && turns == second.turns) continue;
      // The codeword against the cells as read, both in the turned orientation; the weight in
      // the sampled cells' order.
      const CodeWord differ = code.encode(decoded->id) ^ received;
      std::array<bool, 36> disagrees{};
      for (CodeWord bits = differ; bits != 0; bits &= bits - 1)
        disagrees[rotation.cell_of_bit[turns][__builtin_ctzll(bits)]] = true;
      float weight = 0.0f;
      int disagreements = 0;
      for (int p = 0; p < 36; ++p) {
        if (!disagrees[p]) continue;
        weight += reliability[p];
        ++disagreements;
      }
      const Candidate candidate{decoded->id, turns, disagreements, weight};
      if (weight < best.weight) {
        second = best;
        best = candidate;
      } else if (weight < second.weight) {
        second = candidate;
      }
    }
  }
  if (best.id < 0 || best.disagreements > kMaxDisagreements || best.weight > kMaxWeight)
    return std::nullopt;
  if (second.id >= 0 && second.weight - best.weight < kMinMargin) return std::nullopt;
  const float confidence = std::max(0.05f, 0.5f - 0.25f * best.weight);
  return CodeDecode{best.id, best.turns, best.disagreements, confidence};
}

// The cells as fractions between their local black (0) and white (1) levels, with an unsharp mask
// against the mean of the given neighbours (cells off the grid are the black border): a lone
// white cell that blur has dimmed below half is lifted back above it, a lone black cell pushed
// down.
using CellOffset = std::array<int, 2>;  // rows, columns

std::array<float, 36> sharpenedLevels(const MarkerSamples& samples,
                                      std::span<const CellOffset> neighbours, float amount) {
  std::array<float, 36> level{}, sharp{};
  const float half_contrast = std::max(1.0f, samples.contrast * 0.5f);
  for (int i = 0; i < 36; ++i)
    level[i] = 0.5f + (samples.cells[i] - samples.thresholds[i]) / (2.0f * half_contrast);
  auto at = [&](int r, int c) {
    return r < 0 || r > 5 || c < 0 || c > 5 ? 0.0f : level[r * 6 + c];
  };
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      float around = 0.0f;
      for (const auto& [dr, dc] : neighbours) around += at(r + dr, c + dc);
      around /= static_cast<float>(neighbours.size());
      sharp[r * 6 + c] = level[r * 6 + c] + amount * (level[r * 6 + c] - around);
    }
  }
  return sharp;
}

struct Reading {
  CodeGrid cells{};
  std::array<float, 36> reliability{};
};

Reading readingOf(const std::array<float, 36>& levels) {
  Reading reading;
  for (int i = 0; i < 36; ++i) {
    reading.cells[i] = levels[i] > 0.5f;
    reading.reliability[i] = std::abs(levels[i] - 0.5f) * 2.0f;
  }
  return reading;
}

// Sharpening overshoots, so a sharpened cell may read beyond full contrast (reliability over 1),
// and a hard decode of a sharpened reading may overrule such a cell. Beyond twice full contrast
// it is not trusted, and Chase judges the reading instead: a motion-blurred marker once read as
// another id in another turn by overruling a cell at 4.6 (directional reading), while right
// readings overrule cells well under that (under 2 in the four-neighbour readings, where this
// bound refuses none).
constexpr float kMaxOverruled = 2.0f;

// Each extra reading (sharpened, then along each of four directions) is another chance for a
// smeared code to land within 2 bits of a wrong codeword: their hard decodes may correct 1 bit,
// and a reading 2 bits off goes to Chase decoding, which weighs the cells' reliability.
constexpr int kMaxExtraReadingCorrections = 1;

// The most decisively read cell a BCH decode overrules (0 when it corrected none).
float strongestCorrection(const IdCode& code, const CodeDecode& decoded, const Reading& reading) {
  const Rotations& rotation = rotations();
  const CodeWord differ =
      code.encode(decoded.id) ^ rotation.turned(reading.cells, decoded.orientation);
  float strongest = 0.0f;
  for (CodeWord bits = differ; bits != 0; bits &= bits - 1) {
    const int cell = rotation.cell_of_bit[decoded.orientation][__builtin_ctzll(bits)];
    strongest = std::max(strongest, reading.reliability[cell]);
  }
  return strongest;
}

}  // namespace

std::optional<CodeDecode> decodeCode(const IdCode& code, const MarkerSamples& samples,
                                     CodeReadings readings) {
  CodeGrid sampled{};
  std::array<float, 36> reliability{};
  const float half_contrast = std::max(1.0f, samples.contrast * 0.5f);
  for (int i = 0; i < 36; ++i) {
    sampled[i] = samples.cells[i] > samples.thresholds[i];
    reliability[i] = std::abs(samples.cells[i] - samples.thresholds[i]) / half_contrast;
  }
  bool ambiguous = false;
  const std::optional<CodeDecode> hard = hardDecode(code, sampled, ambiguous);
  if (hard && !ambiguous) return hard;
  if (ambiguous || !code.corrects_errors || readings == CodeReadings::Plain) return std::nullopt;
  const bool chase = readings == CodeReadings::SharpenedAndChase;
  // Hard decoding corrects up to 2 cells in every turn: when it found no codeword, each one
  // disagrees with 3 cells or more; when it found two equally near, nothing is known.
  constexpr int kBeyondHard = 3;
  auto nearest = [](const std::optional<CodeDecode>& decoded) { return decoded ? 0 : kBeyondHard; };
  // Blur: read the sharpened cells, then Chase-decode the plain and the sharpened reading.
  constexpr std::array<CellOffset, 4> kFourNeighbours{{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  const Reading sharpened = readingOf(sharpenedLevels(samples, kFourNeighbours, 1.0f));
  int sharpened_nearest = kBeyondHard;
  if (sharpened.cells != sampled) {
    const std::optional<CodeDecode> again = hardDecode(code, sharpened.cells, ambiguous);
    if (again && !ambiguous && again->corrected_bits <= kMaxExtraReadingCorrections &&
        strongestCorrection(code, *again, sharpened) <= kMaxOverruled)
      return CodeDecode{again->id, again->orientation, again->corrected_bits,
                        again->confidence * 0.9f};
    sharpened_nearest = nearest(again);
  }
  if (chase) {
    if (auto soft = chaseDecode(code, sampled, reliability, kBeyondHard)) return soft;
    if (auto soft = chaseDecode(code, sharpened.cells, sharpened.reliability, sharpened_nearest))
      return soft;
  }
  // Motion blur smears each cell into its neighbours along one direction: sharpened against
  // those two alone, along the grid's rows, columns and diagonals (within 22.5 degrees of any
  // direction). Across the smear nothing spread, so sharpening there too (the four-neighbour
  // reading) only adds noise; along it a cell's darkness went into two neighbours rather than
  // four, so it is sharpened harder (1.5 against the four-neighbour reading's 1.0).
  constexpr float kDirectionalAmount = 1.5f;
  constexpr std::array<CellOffset, 4> kDirections{{{0, 1}, {1, 0}, {1, 1}, {1, -1}}};
  for (const CellOffset& along : kDirections) {
    const std::array<CellOffset, 2> ends{along, CellOffset{-along[0], -along[1]}};
    const Reading directional = readingOf(sharpenedLevels(samples, ends, kDirectionalAmount));
    const std::optional<CodeDecode> again = hardDecode(code, directional.cells, ambiguous);
    if (again && !ambiguous && again->corrected_bits <= kMaxExtraReadingCorrections &&
        strongestCorrection(code, *again, directional) <= kMaxOverruled)
      return CodeDecode{again->id, again->orientation, again->corrected_bits,
                        again->confidence * 0.8f};
    if (!chase) continue;
    if (auto soft = chaseDecode(code, directional.cells, directional.reliability, nearest(again)))
      return soft;
  }
  return std::nullopt;
}

}  // namespace arbci::vision
