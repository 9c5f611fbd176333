// The passes of the square-marker search after its first one. The first pass thresholds the frame
// by tiles, labels its dark components and fits a quad to each outline. Each later pass looks
// again only where an earlier one left an outline that nearly was a marker (blur thinned or broke
// its border, motion smeared it into fragments, something covers a corner), so a frame without
// such near misses costs nothing more. Their parameters are settings: `tracker.passes` in a
// session file, with their defaults and ranges in vision::searchPassesSchema() (vision/settings.h);
// docs/tracker.md says what each pass catches and what it costs.
#pragma once

namespace arbci::vision {

struct SearchPasses {
  SearchPasses();  // every parameter at its schema default

  // Smoothing (Smoothing::Auto): a frame whose estimated sensor noise is at least this many grey
  // levels is smoothed (3x3 binomial) before the first pass; below it, smoothing would only soften
  // small markers further.
  double smooth_above_noise;

  // A marker found on a frame smoothed for its compression (its JPEG blocks; or by
  // Smoothing::Always) has its sides moved onto the frame's own edges: the smoothing widens each
  // edge, and a wider edge meets the border's inner edge and the margin's outer edge sooner, which
  // pulls a small marker's corners inward. A frame smoothed for its noise keeps the smoothed edges
  // (the steadier there), and so does a marker whose edges are smeared by motion (as
  // blurred_edges judges a ramp): across a smear the smoothing moves little, and the frame's
  // compression ringing more. A corner that would move more than `most_move_px` stays: the
  // correction is a fraction of a pixel, and a larger move is noise or smear.
  struct PlaceOnFrame {
    bool enabled;
    double most_move_px;
  } place_on_frame;

  // A component ringed round light cells whose outline is no quadrilateral may be a marker with
  // something over a corner (a finger, the gripper): its four sides are fitted on their visible
  // runs and intersected, and its code read where enough cells show (BCH corrects the rest).
  // A light occluder cuts the border open: the component then encloses nothing and its outline
  // runs in round the code cells. Such a component is tried when its outline is at least
  // `cut_open_outline` times its box's perimeter (a blob's or a smear's is about as long) and it
  // fills under `cut_open_fill` of its box and of its convex hull (a solid shape fills nearly all).
  struct OccludedCorners {
    bool enabled;
    int max_tries;  // components a frame, in the order labelled
    double cut_open_outline;
    double cut_open_fill;
  } occluded_corners;

  // A component whose outline did not fit a quad but whose hull is a quadrilateral with dark
  // pixels along every side (a border that blur thinned or broke; a letter leaves a side empty)
  // is thresholded again around its box with a lighter split, then, on a smoothed frame, on the
  // unsmoothed one (a thin, steeply tilted marker that smoothing erased).
  struct NearMisses {
    bool enabled;
    // Regions a frame: those enclosing a hole first (a marker's border encloses its code), then
    // the largest. Noise leaves many small near misses, and markers are seldom the smallest.
    int max_regions;
    int max_regions_decimated;  // search_decimate 2, whose margin to its speed target is thinner
    int max_side_px;            // a larger outline is not one that blur thinned
    int margin_px;              // added round the region's box
    // Sixteenths of a tile's grey range where a pixel counts as dark: lighter than the first
    // pass's 7, so that more of a blurred border counts as dark and closes.
    int split;
    // A region joined with the quads or failed outlines it overlaps (a smear that cut a marker in
    // two) is kept to this many times its own area: beyond that the pieces were clutter.
    int max_join_growth;
  } near_misses;

  // Full search only: a component ringed round two or more holes, as a marker's border is, whose
  // hull lost a thin corner to blur; retried as a near miss, the largest first.
  struct CutCorners {
    bool enabled;
    int max_regions;
  } cut_corners;

  // Motion blur washes a border out across its direction and leaves a marker as several dark
  // fragments. Failed components this close become one region (of a marker's size, not inside a
  // marker found), thresholded again at `split`; two such groups whose boxes overlap (a smear's
  // two ends) are also tried as one where neither gave a quad.
  struct Fragments {
    bool enabled;
    int max_groups;        // a frame, the largest first
    int gap_px;            // failed components closer than this are one region
    int split;             // sixteenths of a tile's range; lighter still than a near miss's
    int max_joined_pairs;  // pairs of overlapping groups tried as one, a frame
  } fragments;

  // search_decimate 2: a marker seen nearly edge-on is a thin outline on the reduced image, its
  // code cells 1 px or less. A near miss narrower than `max_width_px` (its area over its longest
  // side, reduced-image px) and at least `min_length_px` long is labelled again on the frame,
  // where its cells show; shorter ones are too small to read edge-on. A reduced quad narrower than
  // `refine_width_px` is moved onto the reduced image's edges before the frame's, which its
  // contour's lines alone may not reach.
  struct ThinOnFrame {
    bool enabled;
    double max_width_px;
    double min_length_px;
    double refine_width_px;
  } thin_on_frame;

  // Full search: a region no earlier retry read is thresholded once more, halfway between its
  // own darkest and lightest grey, where these span at least `min_range` of the frame's range (a
  // black border and a white quiet zone both inside it). A smear that greys a border where the
  // frame is mid-grey leaves the tiles' thresholds following the background; the marker's own
  // midpoint still parts black from white.
  struct MidGrey {
    bool enabled;
    double min_range;  // fraction of the frame's grey range
  } mid_grey;

  // A quad with a marker's border whose code does not read is moved onto motion-blurred edges
  // (each side onto the middle of its smeared ramp) and read again, without Chase decoding (a
  // second reading doubles a decoy's chance), when a corner moved at least `min_move_px`: sides
  // that hardly moved read as before.
  struct BlurredEdges {
    bool enabled;
    double min_move_px;
  } blurred_edges;

  // A finger over a corner that also reaches the background joins the border's dark component to
  // the background's: no outline of the marker is left to fit. Quads are then assembled from
  // straight edge segments (OpenCV's LSD on the frame at half resolution, as AprilTag 3 fits its
  // quads to edge points): four segments dark on their inner side that follow one another
  // turning right, each ending within `max_corner_gap` of its side from the next corner, except
  // at one covered corner (within `max_covered_gap`). Segments whose sides differ by less than
  // `min_contrast` grey levels are left out. At most `max_quads` candidates a frame are read.
  struct EdgeSegments {
    bool enabled;
    double min_contrast;
    double max_corner_gap;
    double max_covered_gap;
    int max_quads;
  } edge_segments;
};

}  // namespace arbci::vision
