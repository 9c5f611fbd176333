// Private: reads the sampled 6x6 cells as a simple or BCH ID in all four rotations and keeps the
// unambiguous best, as ARToolKitPlus (fewest corrected bits; a tie between rotations is rejected
// rather than guessed). For BCH IDs, when that hard decoding fails, a Chase decoder may try
// again: the least reliable cells (closest to their threshold) are flipped in every combination,
// each trial is hard-decoded, and the codeword whose disagreements with the cells weigh least
// (summed reliability) wins if it is clearly better than any other. It reads the cells as sampled,
// sharpened against their four neighbours (blur), and sharpened along each of the grid's four
// directions in turn (motion blur).
#pragma once

#include <optional>

#include "arbci/vision/marker_family.h"
#include "marker_sampler.h"

namespace arbci::vision {

struct CodeDecode {
  int id = -1;
  int orientation = 0;  // clockwise quarter turns from the sampled grid to the printed grid
  int corrected_bits = 0;
  float confidence = 0.0f;
};

// How hard decodeCode() tries once the plain hard decoding fails (a code that corrects errors): not
// at all, hard decoding of the sharpened readings, or those and Chase decoding.
enum class CodeReadings { Plain, Sharpened, SharpenedAndChase };

std::optional<CodeDecode> decodeCode(const IdCode& code, const MarkerSamples& samples,
                                     CodeReadings readings);

}  // namespace arbci::vision
