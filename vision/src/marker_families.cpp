#include "arbci/vision/marker_family.h"

#include <string>

namespace arbci::vision {

// Each in its own file under families/.
MarkerFamilyRegistry::Entry bchFamily();
MarkerFamilyRegistry::Entry simpleFamily();
MarkerFamilyRegistry::Entry templateFamily();
MarkerFamilyRegistry::Entry arucoFamily();
MarkerFamilyRegistry::Entry aprilTagFamily();

const MarkerFamilyRegistry& markerFamilies() {
  static const MarkerFamilyRegistry registry = [] {
    MarkerFamilyRegistry r("marker family", "tracker.kind");
    r.add(bchFamily());
    r.add(simpleFamily());
    r.add(templateFamily());
    r.add(arucoFamily());
    r.add(aprilTagFamily());
    return r;
  }();
  return registry;
}

const MarkerFamily& familyOf(MarkerKind kind) {
  for (const auto& entry : markerFamilies().entries())
    if (entry.name == kind.name) return entry.make;
  return markerFamilies().at(std::string(kind.name)).make;  // throws, naming the families
}

MarkerKind markerKindFromString(const std::string& text) {
  return MarkerKind{markerFamilies().at(text).name};
}

std::string toString(MarkerKind kind) {
  return std::string(kind.name);
}

}  // namespace arbci::vision
