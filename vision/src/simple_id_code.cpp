// Simple IDs: the 9-bit id repeated in four 9-bit fields, XOR a fixed mask.
#include "arbci/vision/id_codes.h"

namespace arbci::vision {
namespace {
constexpr CodeWord kSimpleMask = 0x6DC269C27ULL;
}

CodeWord SimpleIdCode::encode(int id) {
  const CodeWord value = static_cast<CodeWord>(id) & 0x1FF;
  return (value | value << 9 | value << 18 | value << 27) ^ kSimpleMask;
}

std::optional<DecodedId> SimpleIdCode::decode(CodeWord word) {
  const CodeWord plain = (word ^ kSimpleMask) & kCodeMask;
  int id = 0;
  int split_votes = 0;  // 3:1 majorities
  for (int bit = 0; bit < 9; ++bit) {
    int ones = 0;
    for (int field = 0; field < 4; ++field) ones += (plain >> (bit + 9 * field)) & 1U;
    if (ones == 2) return std::nullopt;  // 2:2, no majority: confidence 0
    if (ones == 1 || ones == 3) ++split_votes;
    if (ones >= 3) id |= 1 << bit;
  }
  // Confidence is the mean over the 9 votes of 1 (4:0) or 0.5 (3:1); below 0.9 it is rejected.
  const float confidence = (9.0f - 0.5f * static_cast<float>(split_votes)) / 9.0f;
  if (confidence < 0.9f) return std::nullopt;
  return DecodedId{id, split_votes, confidence};
}

}  // namespace arbci::vision
