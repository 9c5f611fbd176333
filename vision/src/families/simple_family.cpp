// ARToolKitPlus's simple ids: 9 bits, each written four times and read by majority.
#include "arbci/vision/marker_family.h"

namespace arbci::vision {

MarkerFamilyRegistry::Entry simpleFamily() {
  static const IdCode code{SimpleIdCode::kMaxId, &SimpleIdCode::decode, &SimpleIdCode::encode};
  MarkerFamily family;
  family.border = 0.25;
  family.in_sessions = true;
  family.code = &code;
  return {"simple", "ARToolKitPlus's simple ids 0-511 (border 0.25)", std::move(family)};
}

}  // namespace arbci::vision
