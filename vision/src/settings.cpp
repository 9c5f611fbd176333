#include "arbci/vision/settings.h"

namespace arbci::vision {

const MarkerFamilyRegistry& markerFamilies() {
  static const MarkerFamilyRegistry registry = [] {
    MarkerFamilyRegistry r("marker family", "tracker.kind");
    r.add({"bch",
           "ARToolKitPlus's BCH-coded ids 0-4095 (thin border 0.125), errors corrected",
           {MarkerKind::Bch, 0.125, true, true}});
    r.add({"simple",
           "ARToolKitPlus's simple ids 0-511 (border 0.25)",
           {MarkerKind::Simple, 0.25, true, true}});
    r.add({"template",
           "trained template patterns (arbci marker train; detect --pattern)",
           {MarkerKind::Template, 0.25}});
    r.add({"aruco", "an OpenCV ArUco dictionary (detect --dictionary)", {MarkerKind::Aruco, 0.25}});
    r.add({"apriltag",
           "an AprilTag family, found by libapriltag (detect --dictionary)",
           {MarkerKind::AprilTag, 0.25}});
    return r;
  }();
  return registry;
}

const core::Schema<DetectorConfig>& detectorSchema() {
  static const core::Schema<DetectorConfig> table = [] {
    using Json = nlohmann::json;
    core::Schema<DetectorConfig> t("tracker", "The marker tracker");
    core::Key kind{"kind", core::Type::Text, "bch", "the markers' family (marker families)"};
    kind.choices = [] { return markerFamilies().names(); };
    t.custom(
         kind,
         [](DetectorConfig& d, const Json& j) {
           d.kind = markerKindFromString(j.get<std::string>());
         },
         [](const DetectorConfig& d) { return Json(toString(d.kind)); })
        .number("border", &DetectorConfig::border, 0.125, 0.05, 0.4,
                "the black border's width as a fraction of the marker's side")
        .integer("search_decimate", &DetectorConfig::search_decimate, 1, 1, 2,
                 "1: search at full resolution; 2: on the frame averaged over 2x2 pixels, corners "
                 "refined at full resolution (faster; markers need about 24 px a side); kind "
                 "apriltag: libapriltag's quad_decimate")
        .boolean("apriltag_refine_edges", &DetectorConfig::apriltag_refine_edges, true,
                 "kind apriltag: libapriltag's edge refinement (the library's default); false "
                 "leaves the corners where its quad fit put them");
    return t;
  }();
  return table;
}

DetectorConfig::DetectorConfig() {
  detectorSchema().applyDefaults(*this);
}

}  // namespace arbci::vision
