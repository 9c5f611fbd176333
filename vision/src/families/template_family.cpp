// Trained patterns (ARToolKit .patt): the square's inside matched to each in its four turns.
#include "arbci/vision/marker_family.h"

namespace arbci::vision {

MarkerFamilyRegistry::Entry templateFamily() {
  MarkerFamily family;
  family.border = 0.25;
  family.templates = true;
  return {"template", "trained template patterns (arbci marker train; detect --pattern)",
          std::move(family)};
}

}  // namespace arbci::vision
