#include "arbci/vision/settings.h"

namespace arbci::vision {

namespace {

using Passes = SearchPasses;

const core::Schema<Passes::OccludedCorners>& occludedCornersSchema() {
  static const core::Schema<Passes::OccludedCorners> t = [] {
    core::Schema<Passes::OccludedCorners> s(
        "occluded_corners",
        "a component ringed round light cells whose outline is no quadrilateral (a finger or the "
        "gripper over a corner): its sides fitted on their visible runs and intersected");
    s.boolean("enabled", &Passes::OccludedCorners::enabled, true, "run this pass")
        .integer("max_tries", &Passes::OccludedCorners::max_tries, 4, 0, 64,
                 "components fitted so a frame, in the order labelled")
        .number("cut_open_outline", &Passes::OccludedCorners::cut_open_outline, 1.2, 0.5, 10.0,
                "a component enclosing nothing (a border a light occluder cut open) is tried when "
                "its outline is at least this many times its box's perimeter")
        .number("cut_open_fill", &Passes::OccludedCorners::cut_open_fill, 0.8, 0.0, 1.0,
                "and it fills less than this fraction of its box and of its convex hull");
    return s;
  }();
  return t;
}

const core::Schema<Passes::NearMisses>& nearMissesSchema() {
  static const core::Schema<Passes::NearMisses> t = [] {
    core::Schema<Passes::NearMisses> s(
        "near_misses",
        "an outline that did not fit a quad but whose hull is a quadrilateral with dark along "
        "every side (a border blur thinned or broke), thresholded again around it with a lighter "
        "split, then on the unsmoothed frame");
    s.boolean("enabled", &Passes::NearMisses::enabled, true, "run this pass")
        .integer("max_regions", &Passes::NearMisses::max_regions, 12, 0, 100,
                 "regions a frame at full resolution, those enclosing a hole first, then the "
                 "largest")
        .integer("max_regions_decimated", &Passes::NearMisses::max_regions_decimated, 8, 0, 100,
                 "regions a frame with search_decimate 2")
        .integer("max_side_px", &Passes::NearMisses::max_side_px, 160, 16, 4000,
                 "outlines larger than this are not retried (blur does not thin their border)",
                 "px")
        .integer("margin_px", &Passes::NearMisses::margin_px, 14, 1, 64,
                 "added round the region's box", "px")
        .integer("split", &Passes::NearMisses::split, 9, 1, 15,
                 "sixteenths of a tile's grey range below which a pixel is dark (the first pass: "
                 "7)")
        .integer("max_join_growth", &Passes::NearMisses::max_join_growth, 3, 1, 20,
                 "a region joined with the quads or outlines it overlaps is kept to this many "
                 "times its area");
    return s;
  }();
  return t;
}

const core::Schema<Passes::EdgeSegments>& edgeSegmentsSchema() {
  static const core::Schema<Passes::EdgeSegments> t = [] {
    core::Schema<Passes::EdgeSegments> s(
        "edge_segments",
        "quads assembled from straight edge segments (LSD at half resolution): a marker whose "
        "covered corner joined its border to the background");
    s.boolean("enabled", &Passes::EdgeSegments::enabled, true, "run this pass")
        .number("min_contrast", &Passes::EdgeSegments::min_contrast, 16.0, 1.0, 255.0,
                "grey levels between a segment's dark and light sides")
        .number("max_corner_gap", &Passes::EdgeSegments::max_corner_gap, 0.12, 0.0, 0.5,
                "a side's segment ends this near its corner, as a fraction of the side")
        .number("max_covered_gap", &Passes::EdgeSegments::max_covered_gap, 0.45, 0.0, 0.9,
                "at one covered corner, this near, as a fraction of the side")
        .integer("max_quads", &Passes::EdgeSegments::max_quads, 16, 0, 200,
                 "candidates read a frame, from the longest sides");
    return s;
  }();
  return t;
}

const core::Schema<Passes::CutCorners>& cutCornersSchema() {
  static const core::Schema<Passes::CutCorners> t = [] {
    core::Schema<Passes::CutCorners> s(
        "cut_corners",
        "full resolution: a component ringed round two or more holes whose hull lost a thin "
        "corner to blur, retried as a near miss");
    s.boolean("enabled", &Passes::CutCorners::enabled, true, "run this pass")
        .integer("max_regions", &Passes::CutCorners::max_regions, 2, 0, 50,
                 "regions a frame, the largest first");
    return s;
  }();
  return t;
}

const core::Schema<Passes::Fragments>& fragmentsSchema() {
  static const core::Schema<Passes::Fragments> t = [] {
    core::Schema<Passes::Fragments> s(
        "fragments",
        "failed components close together (a border motion blur washed out into pieces), "
        "grouped into one region and thresholded again");
    s.boolean("enabled", &Passes::Fragments::enabled, true, "run this pass")
        .integer("max_groups", &Passes::Fragments::max_groups, 6, 0, 100,
                 "groups a frame, the largest first")
        .integer("gap_px", &Passes::Fragments::gap_px, 4, 1, 32,
                 "failed components closer than this are one group", "px")
        .integer("split", &Passes::Fragments::split, 11, 1, 15,
                 "sixteenths of a tile's grey range below which a pixel is dark")
        .integer("max_joined_pairs", &Passes::Fragments::max_joined_pairs, 2, 0, 20,
                 "pairs of overlapping groups (a smear's two ends) also tried as one, a frame");
    return s;
  }();
  return t;
}

const core::Schema<Passes::ThinOnFrame>& thinOnFrameSchema() {
  static const core::Schema<Passes::ThinOnFrame> t = [] {
    core::Schema<Passes::ThinOnFrame> s(
        "thin_on_frame",
        "search_decimate 2: a thin near miss (a marker seen nearly edge-on) labelled again on "
        "the full-resolution frame, where its code cells show");
    s.boolean("enabled", &Passes::ThinOnFrame::enabled, true, "run this pass")
        .number("max_width_px", &Passes::ThinOnFrame::max_width_px, 10.0, 1.0, 100.0,
                "narrower than this (area over longest side) is thin", "reduced-image px")
        .number("min_length_px", &Passes::ThinOnFrame::min_length_px, 20.0, 1.0, 1000.0,
                "and at least this long (shorter ones are too small to read edge-on)",
                "reduced-image px")
        .number("refine_width_px", &Passes::ThinOnFrame::refine_width_px, 8.0, 0.0, 100.0,
                "a reduced quad narrower than this is refined on the reduced image before the "
                "frame",
                "reduced-image px");
    return s;
  }();
  return t;
}

const core::Schema<Passes::MidGrey>& midGreySchema() {
  static const core::Schema<Passes::MidGrey> t = [] {
    core::Schema<Passes::MidGrey> s(
        "mid_grey",
        "full resolution: a region no retry read, thresholded once more halfway between its own "
        "darkest and lightest grey");
    s.boolean("enabled", &Passes::MidGrey::enabled, true, "run this pass")
        .number("min_range", &Passes::MidGrey::min_range, 0.85, 0.0, 1.0,
                "only where the region's grey range is at least this fraction of the frame's");
    return s;
  }();
  return t;
}

const core::Schema<Passes::PlaceOnFrame>& placeOnFrameSchema() {
  static const core::Schema<Passes::PlaceOnFrame> t = [] {
    core::Schema<Passes::PlaceOnFrame> s(
        "place_on_frame",
        "a marker found on a frame smoothed for its compression, its sides moved onto the "
        "frame's own edges (not where they are smeared)");
    s.boolean("enabled", &Passes::PlaceOnFrame::enabled, true, "run this pass")
        .number("most_move_px", &Passes::PlaceOnFrame::most_move_px, 0.3, 0.0, 5.0,
                "a corner that would move further stays where it was found", "px");
    return s;
  }();
  return t;
}

const core::Schema<Passes::BlurredEdges>& blurredEdgesSchema() {
  static const core::Schema<Passes::BlurredEdges> t = [] {
    core::Schema<Passes::BlurredEdges> s(
        "blurred_edges",
        "a quad with a marker's border whose code does not read, moved onto motion-blurred "
        "edges and read again");
    s.boolean("enabled", &Passes::BlurredEdges::enabled, true, "run this pass")
        .number("min_move_px", &Passes::BlurredEdges::min_move_px, 1.5, 0.0, 20.0,
                "read again only when a corner moved at least this far", "px");
    return s;
  }();
  return t;
}

}  // namespace

const core::Schema<SearchPasses>& searchPassesSchema() {
  static const core::Schema<SearchPasses> table = [] {
    core::Schema<SearchPasses> t(
        "passes",
        "the square-marker search's passes after its first (docs/tracker.md: what each catches "
        "and costs)");
    t.number("smooth_above_noise", &SearchPasses::smooth_above_noise, 2.5, 0.0, 64.0,
             "smoothing auto: a frame with at least this much estimated sensor noise is smoothed "
             "before thresholding",
             "grey levels")
        .section("place_on_frame", &SearchPasses::place_on_frame, placeOnFrameSchema())
        .section("occluded_corners", &SearchPasses::occluded_corners, occludedCornersSchema())
        .section("near_misses", &SearchPasses::near_misses, nearMissesSchema())
        .section("cut_corners", &SearchPasses::cut_corners, cutCornersSchema())
        .section("fragments", &SearchPasses::fragments, fragmentsSchema())
        .section("thin_on_frame", &SearchPasses::thin_on_frame, thinOnFrameSchema())
        .section("mid_grey", &SearchPasses::mid_grey, midGreySchema())
        .section("blurred_edges", &SearchPasses::blurred_edges, blurredEdgesSchema())
        .section("edge_segments", &SearchPasses::edge_segments, edgeSegmentsSchema());
    return t;
  }();
  return table;
}

SearchPasses::SearchPasses() {
  searchPassesSchema().applyDefaults(*this);
}

const core::Schema<DetectorConfig>& detectorSchema() {
  static const core::Schema<DetectorConfig> table = [] {
    using Json = nlohmann::json;
    core::Schema<DetectorConfig> t("tracker", "The marker tracker");
    // ARToolKitPlus's BCH ids, at that family's own border.
    const std::string family = "bch";
    core::Key kind{"kind", core::Type::Text, family, "the markers' family (marker families)"};
    kind.choices = [] { return markerFamilies().names(); };
    t.custom(
         kind,
         [](DetectorConfig& d, const Json& j) {
           d.kind = markerKindFromString(j.get<std::string>());
         },
         [](const DetectorConfig& d) { return Json(toString(d.kind)); })
        .number("border", &DetectorConfig::border, markerFamilies().at(family).make.border, 0.05,
                0.4, "the black border's width as a fraction of the marker's side")
        .integer("search_decimate", &DetectorConfig::search_decimate, 1, 1, 2,
                 "1: search at full resolution; 2: on the frame averaged over 2x2 pixels, corners "
                 "refined at full resolution (faster; markers need about 24 px a side); kind "
                 "apriltag: libapriltag's quad_decimate")
        .boolean("apriltag_refine_edges", &DetectorConfig::apriltag_refine_edges, true,
                 "kind apriltag: libapriltag's edge refinement (the library's default); false "
                 "leaves the corners where its quad fit put them")
        .section("passes", &DetectorConfig::passes, searchPassesSchema());
    return t;
  }();
  return table;
}

DetectorConfig::DetectorConfig() {
  detectorSchema().applyDefaults(*this);
}

}  // namespace arbci::vision
