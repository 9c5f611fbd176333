#include "code_decoder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "arbci/vision/id_codes.h"

namespace arbci::vision {
namespace {

std::optional<DecodedId> decodeWord(MarkerKind kind, CodeWord word) {
  return kind == MarkerKind::Simple ? SimpleIdCode::decode(word) : BchCode::decode(word);
}

// ARToolKitPlus's rule: the rotation with the fewest corrected bits; a tie is ambiguous.
std::optional<CodeDecode> hardDecode(MarkerKind kind, const CodeGrid& sampled, bool& ambiguous) {
  std::optional<CodeDecode> best;
  ambiguous = false;
  for (int turns = 0; turns < 4; ++turns) {
    const auto decoded = decodeWord(kind, gridToWord(rotateClockwise(sampled, turns)));
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
// other candidate (another id or orientation) by kMinMargin.
std::optional<CodeDecode> chaseDecode(const CodeGrid& sampled,
                                      const std::array<float, 36>& reliability) {
  constexpr int kFlipped = 6;
  constexpr float kMaxReliabilityToFlip = 0.5f, kMaxWeight = 1.2f, kMinMargin = 0.6f;
  constexpr int kMaxDisagreements = 5;
  std::array<int, 36> order;
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + kFlipped, order.end(),
                    [&](int a, int b) { return reliability[a] < reliability[b]; });
  int flippable = 0;
  while (flippable < kFlipped && reliability[order[flippable]] < kMaxReliabilityToFlip) ++flippable;

  struct Candidate {
    int id, turns, disagreements;
    float weight;
  };
  Candidate best{-1, 0, 0, 1e9f}, second{-1, 0, 0, 1e9f};
  const CodeWord received = gridToWord(sampled);
  for (int pattern = 0; pattern < (1 << flippable); ++pattern) {
    CodeGrid trial = sampled;
    for (int b = 0; b < flippable; ++b) {
      if (pattern & (1 << b)) trial[order[b]] = !trial[order[b]];
    }
    for (int turns = 0; turns < 4; ++turns) {
      const auto decoded = BchCode::decode(gridToWord(rotateClockwise(trial, turns)));
      if (!decoded) continue;
      // The codeword as it appears in the sampled orientation, against the cells as read.
      const CodeWord codeword =
          gridToWord(rotateClockwise(wordToGrid(BchCode::encode(decoded->id)), 4 - turns));
      const CodeWord differ = codeword ^ received;
      float weight = 0.0f;
      for (int p = 0; p < 36; ++p) {
        if ((differ >> (35 - p)) & 1U) weight += reliability[p];
      }
      const Candidate candidate{decoded->id, turns, __builtin_popcountll(differ), weight};
      if (candidate.id == best.id && candidate.turns == best.turns) continue;
      if (candidate.id == second.id && candidate.turns == second.turns) continue;
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
// over the 4-neighbours (the border around the code is black): a lone white cell that blur has
// dimmed below half is lifted back above it, a lone black cell pushed down.
std::array<float, 36> sharpenedLevels(const MarkerSamples& samples) {
  std::array<float, 36> level{}, sharp{};
  const float half_contrast = std::max(1.0f, samples.contrast * 0.5f);
  for (int i = 0; i < 36; ++i)
    level[i] = 0.5f + (samples.cells[i] - samples.thresholds[i]) / (2.0f * half_contrast);
  constexpr float kAmount = 1.0f;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      auto at = [&](int rr, int cc) {
        return rr < 0 || rr > 5 || cc < 0 || cc > 5 ? 0.0f : level[rr * 6 + cc];
      };
      const float around = 0.25f * (at(r - 1, c) + at(r + 1, c) + at(r, c - 1) + at(r, c + 1));
      sharp[r * 6 + c] = level[r * 6 + c] + kAmount * (level[r * 6 + c] - around);
    }
  }
  return sharp;
}

}  // namespace

std::optional<CodeDecode> decodeCode(MarkerKind kind, const MarkerSamples& samples,
                                     bool soft_decoding) {
  CodeGrid sampled{};
  std::array<float, 36> reliability{};
  const float half_contrast = std::max(1.0f, samples.contrast * 0.5f);
  for (int i = 0; i < 36; ++i) {
    sampled[i] = samples.cells[i] > samples.thresholds[i];
    reliability[i] = std::abs(samples.cells[i] - samples.thresholds[i]) / half_contrast;
  }
  bool ambiguous = false;
  const std::optional<CodeDecode> hard = hardDecode(kind, sampled, ambiguous);
  if (hard && !ambiguous) return hard;
  if (ambiguous || kind != MarkerKind::Bch || !soft_decoding) return std::nullopt;
  // Blur: read the sharpened cells, then Chase-decode the plain and the sharpened reading.
  const std::array<float, 36> sharp = sharpenedLevels(samples);
  CodeGrid sharpened{};
  std::array<float, 36> sharp_reliability{};
  for (int i = 0; i < 36; ++i) {
    sharpened[i] = sharp[i] > 0.5f;
    sharp_reliability[i] = std::abs(sharp[i] - 0.5f) * 2.0f;
  }
  if (sharpened != sampled) {
    const std::optional<CodeDecode> again = hardDecode(kind, sharpened, ambiguous);
    if (again && !ambiguous)
      return CodeDecode{again->id, again->orientation, again->corrected_bits,
                        again->confidence * 0.9f};
  }
  if (auto chase = chaseDecode(sampled, reliability)) return chase;
  return chaseDecode(sharpened, sharp_reliability);
}

}  // namespace arbci::vision
