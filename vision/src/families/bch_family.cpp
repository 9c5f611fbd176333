// ARToolKitPlus's BCH-coded ids: 12 bits in the 36 cells, up to 2 wrong cells corrected.
#include "arbci/vision/marker_family.h"

namespace arbci::vision {

MarkerFamilyRegistry::Entry bchFamily() {
  // Every BCH codeword has 7 or more light cells.
  static const IdCode code{
      BchCode::kMaxId, &BchCode::decode, &BchCode::encode, &BchCode::rotationMargin, true, 7};
  MarkerFamily family;
  family.border = 0.125;
  family.in_sessions = true;
  family.code = &code;
  return {"bch", "ARToolKitPlus's BCH-coded ids 0-4095 (thin border 0.125), errors corrected",
          std::move(family)};
}

}  // namespace arbci::vision
