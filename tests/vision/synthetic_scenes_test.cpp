// The tracker on synthetic frames with exact ground truth (the benchmark's scenes): markers 20 px
// and up, tilted up to 60 degrees, with decoys and clutter, under the five conditions. The tilt is
// from the optical axis here (LayoutOptions' default): the benchmark's steep scenes
// (`--tilt-from axis`), whose markers near the frame's sides are seen nearly edge-on.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_printer.h"
#include "support/marker_scoring.h"
#include "support/synthetic_markers.h"

namespace arbci::vision {
namespace {

using test::Condition;

test::Score run(Condition condition, int frames, const test::LayoutOptions& options = {},
                const DetectorConfig& config = {}) {
  MarkerDetector detector(config);
  test::Score total;
  for (int f = 0; f < frames; ++f) {
    const test::SceneLayout layout = test::makeLayout(options, 5000u + static_cast<unsigned>(f));
    const test::RenderedScene scene =
        test::renderScene(layout, test::MarkerFamily::ArbciBch, condition);
    std::vector<test::FoundMarker> found;
    for (const MarkerDetection& m : detector.detect(scene.image).markers)
      found.push_back({m.id, m.corners});
    total.add(test::scoreFrame(scene.ids, scene.markers, found, /*ordered=*/true));
  }
  return total;
}

// One frame of the benchmark's steep scenes (markers from 48 px, a 2-cell margin, tilted from the
// optical axis), scored.
test::Score scoreFairFrame(std::uint32_t seed, Condition condition, const DetectorConfig& config) {
  test::LayoutOptions fair;
  fair.min_side_px = 48.0f;
  fair.quiet_cells = 2.0f;
  const test::RenderedScene scene =
      test::renderScene(test::makeLayout(fair, seed), test::MarkerFamily::ArbciBch, condition);
  std::vector<test::FoundMarker> found;
  for (const MarkerDetection& m : MarkerDetector(config).detect(scene.image).markers)
    found.push_back({m.id, m.corners});
  return test::scoreFrame(scene.ids, scene.markers, found, /*ordered=*/true);
}

struct Expectation {
  Condition condition;
  double min_recall;
  double max_corner_error;
};

class SyntheticScenes : public testing::TestWithParam<Expectation> {};

TEST_P(SyntheticScenes, FindMarkersWithNoWrongIdAndNoFalsePositive) {
  const Expectation e = GetParam();
  const test::Score score = run(e.condition, 20);
  EXPECT_EQ(score.wrong_id, 0);
  EXPECT_EQ(score.false_positive, 0);
  EXPECT_GE(score.recall(), e.min_recall) << score.found << " of " << score.truth;
  EXPECT_LE(score.meanCornerError(), e.max_corner_error);
}

// Recall floors well below what the benchmark measures (clean 0.99, blur 0.85, noise 0.98,
// uneven light 0.98, combined 0.68 over 100 frames), so a regression, not chance, fails them.
INSTANTIATE_TEST_SUITE_P(Conditions, SyntheticScenes,
                         testing::Values(Expectation{Condition::Clean, 0.93, 0.12},
                                         Expectation{Condition::Blur, 0.75, 0.25},
                                         Expectation{Condition::Noise, 0.9, 0.2},
                                         Expectation{Condition::UnevenLight, 0.9, 0.12},
                                         Expectation{Condition::Combined, 0.5, 0.5}),
                         [](const auto& info) {
                           std::string name = test::toString(info.param.condition);
                           std::erase(name, ' ');
                           return name;
                         });

// Motion blur washes a marker's border out across its direction, leaving dark fragments; they
// are grouped and binarised again. On the benchmark's steep scenes (markers from 48 px, a 2-cell
// margin) these 40 frames give 105/120 (5-15 px blur + JPEG) and 100/120 (9-15 px + JPEG; 97
// before JPEG frames were smoothed); without the fragment retry 97/120 and 88/120. The floors sit
// between.
TEST(SyntheticScenes, ReadsMotionBlurredMarkers) {
  test::LayoutOptions fair;
  fair.min_side_px = 48.0f;
  fair.quiet_cells = 2.0f;
  for (const auto& [condition, floor] :
       {std::pair{Condition::MotionBlurJpeg, 0.85}, std::pair{Condition::FastMotionJpeg, 0.78}}) {
    const test::Score score = run(condition, 40, fair);
    EXPECT_EQ(score.wrong_id, 0) << test::toString(condition);
    EXPECT_EQ(score.false_positive, 0) << test::toString(condition);
    EXPECT_GE(score.recall(), floor)
        << test::toString(condition) << ": " << score.found << " of " << score.truth;
  }
}

// Seed 9009's motion-blurred 51 x 44 px marker (id 3575): sharpened hard along a diagonal, its
// cells read in another turn as id 3201 with 2 corrections, one of them overruling a cell read at
// 4.6 times full contrast. Both searches read it as 3201 before such decodes were left to Chase.
TEST(SyntheticScenes, OverSharpenedMotionBlurIsNotReadAsAnotherId) {
  for (int decimate : {1, 2}) {
    DetectorConfig config;
    config.search_decimate = decimate;
    const test::Score score = scoreFairFrame(9009u, Condition::MotionBlurJpeg, config);
    EXPECT_EQ(score.wrong_id, 0) << "search_decimate " << decimate;
    EXPECT_EQ(score.false_positive, 0) << "search_decimate " << decimate;
    EXPECT_EQ(score.found, 2) << "search_decimate " << decimate;  // the other two markers
  }
}

// A 320 x 240 frame with one upright marker (`side` px, dark 20, light 220) in the middle, on a
// white printed margin (230) over a grey table (150), smeared along a `length` px line at `degrees`
// (a head turning fast) and, with `jpeg`, compressed at quality 50; `corners` its printed corners.
cv::Mat smearedMarkerFrame(int id, int side, double degrees, int length, bool jpeg,
                           test::Corners& corners) {
  const cv::Mat cells = markerCells(MarkerKind::Bch, id, 0.125);
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(150));
  const int margin = 12, left = 160 - side / 2, top = 120 - side / 2;
  frame(cv::Rect(left - margin, top - margin, side + 2 * margin, side + 2 * margin)).setTo(230);
  cv::Mat marker;
  cv::resize(cells, marker, cv::Size(side, side), 0, 0, cv::INTER_NEAREST);
  marker.convertTo(frame(cv::Rect(left, top, side, side)), CV_8U, 200.0 / 255.0, 20.0);
  test::motionBlur(frame, static_cast<float>(length), static_cast<float>(degrees * CV_PI / 180.0));
  if (jpeg) {
    std::vector<std::uint8_t> bytes;
    cv::imencode(".jpg", frame, bytes, {cv::IMWRITE_JPEG_QUALITY, 50});
    frame = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  // Pixel centres are integers: the printed square spans [left - 0.5, left + side - 0.5].
  const float x0 = static_cast<float>(left) - 0.5f, y0 = static_cast<float>(top) - 0.5f;
  const float s = static_cast<float>(side);
  corners = {cv::Point2f(x0, y0), cv::Point2f(x0 + s, y0), cv::Point2f(x0 + s, y0 + s),
             cv::Point2f(x0, y0 + s)};
  return frame;
}

float largestCornerError(const SquareCorners& found, const test::Corners& truth) {
  float largest = 0.0f;
  for (int k = 0; k < 4; ++k)
    largest = std::max(largest, static_cast<float>(cv::norm(found[k] - truth[k])));
  return largest;
}

// A marker smeared along one line (a head turning fast): 6 ids, 44-60 px, a 15 or 17 px line at
// 6 angles, 216 frames. Sharpening the cells against their two neighbours along each of the
// grid's directions reads 62 of them; with the four-neighbour sharpening alone, 49. No wrong id.
TEST(SyntheticScenes, ReadsMarkersSmearedAlongOneLine) {
  int found = 0, frames = 0, wrong = 0;
  for (int id : {17, 300, 1234, 2047, 3001, 4000}) {
    for (int side : {44, 52, 60}) {
      for (double degrees : {0.0, 30.0, 60.0, 90.0, 120.0, 150.0}) {
        for (int length : {15, 17}) {
          test::Corners truth;
          const cv::Mat frame = smearedMarkerFrame(id, side, degrees, length, false, truth);
          MarkerDetector detector(DetectorConfig{});
          for (const MarkerDetection& m : detector.detect(frame).markers)
            (m.id == id ? found : wrong)++;
          ++frames;
        }
      }
    }
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(found, 56) << found << " of " << frames;
}

// Smeared across a side, the border's edge is a ramp as long as the smear, and the search's
// quad ends partway down it, outside the printed edge: 2-7 px too large along the motion on the
// benchmark's fast motion+JPEG frames, too far off to decode. A quad that does not decode is
// placed again on the middle of its sides' ramps. These 324 frames (9-15 px smears, JPEG 50)
// read 228 (full search) and 231 (decimated) before, 256 and 254 after; the markers read only
// after the placement have every corner within 1.2 px of the printed one.
TEST(SyntheticScenes, SmearedMarkersArePlacedOnTheMiddleOfTheirEdgesRamps) {
  for (int decimate : {1, 2}) {
    DetectorConfig config;
    config.search_decimate = decimate;
    MarkerDetector detector(config);
    int found = 0, frames = 0, wrong = 0;
    for (int id : {17, 300, 1234, 2047, 3001, 4000}) {
      for (int side : {44, 52, 60}) {
        for (double degrees : {0.0, 30.0, 60.0, 90.0, 120.0, 150.0}) {
          for (int length : {9, 12, 15}) {
            test::Corners truth;
            const cv::Mat frame = smearedMarkerFrame(id, side, degrees, length, true, truth);
            for (const MarkerDetection& m : detector.detect(frame).markers)
              (m.id == id ? found : wrong)++;
            ++frames;
          }
        }
      }
    }
    EXPECT_EQ(wrong, 0) << "search_decimate " << decimate;
    EXPECT_GE(found, 245) << found << " of " << frames << ", search_decimate " << decimate;
  }
  // One of them: smeared 15 px at 30 degrees, it was not read; placed on its ramps, it is read
  // with its corners within 1.1 px.
  test::Corners truth;
  const cv::Mat frame = smearedMarkerFrame(1234, 52, 30.0, 15, true, truth);
  const auto markers = MarkerDetector(DetectorConfig{}).detect(frame).markers;
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].id, 1234);
  EXPECT_LE(largestCornerError(markers[0].corners, truth), 1.1f);
}

// The search on the frame averaged over 2x2 pixels, corners refined on the frame. Its adaptive
// threshold keeps the frame's 4 px tiles (2 px of the halved frame): with 4 px tiles there, a
// marker's 2-cell quiet zone is as narrow as the threshold's neighbourhood, and under uneven
// light large markers merged with their surroundings (41 of these 60 read).
TEST(SyntheticScenes, DecimatedSearchReadsFairScenesAsTheFullOne) {
  test::LayoutOptions fair;
  fair.min_side_px = 48.0f;
  fair.quiet_cells = 2.0f;
  DetectorConfig decimated;
  decimated.search_decimate = 2;
  for (Condition condition : {Condition::Clean, Condition::Noise, Condition::UnevenLight}) {
    const test::Score full = run(condition, 20, fair);
    const test::Score half = run(condition, 20, fair, decimated);
    EXPECT_EQ(half.wrong_id, 0) << test::toString(condition);
    EXPECT_EQ(half.false_positive, 0) << test::toString(condition);
    EXPECT_GE(half.recall(), 0.95)
        << test::toString(condition) << ": " << half.found << " of " << half.truth;
    // Refined on the frame's edges: corners as accurate as the full search's.
    EXPECT_LE(half.meanCornerError(), full.meanCornerError() + 0.03) << test::toString(condition);
  }
}

// Clean frames on which the decimated search once missed a plainly readable marker.
// - Seed 9044's marker (id 1071) is skewed into a rhombus 15 x 71 px: on the halved frame its
//   code cells merge with the border into an outline 7 px across with no hole, whose retry there
//   gives a quad that does not decode. Labelled again on the frame, it is read.
// - Seed 9268's marker (id 1030, 39 x 75 px, tilted) has an acute corner that the halved
//   frame's binarisation chamfers: its hull runs 3 px off the chord of the side beside it (2.5
//   allowed) 4.5 px from the corner. Held to the chord there, the outline was no quad.
// - Seed 9723's marker (id 3730) is a rhombus 14 x 78 px, seed 9635's (id 2790) 15 x 96 px: the
//   halved frame breaks each into a ringed thin piece and an open one, and the frame was labelled
//   around the ringed piece alone, the marker cut off at its end.
TEST(SyntheticScenes, DecimatedSearchReadsEveryMarkerOfFramesItOnceMissedOneOf) {
  DetectorConfig decimated;
  decimated.search_decimate = 2;
  for (const std::uint32_t seed : {9044u, 9268u, 9723u, 9635u}) {
    const test::Score score = scoreFairFrame(seed, Condition::Clean, decimated);
    EXPECT_EQ(score.found, 3) << "seed " << seed;
    EXPECT_EQ(score.wrong_id, 0) << "seed " << seed;
    EXPECT_EQ(score.false_positive, 0) << "seed " << seed;
  }
}

// A marker read from one frame of the benchmark's default scenes (tilted from the line of sight)
// or of its small-marker scenes, by the decimated or the full search, with no wrong id and no
// false positive in that frame.
struct ReadCase {
  std::uint32_t seed;
  Condition condition;
  cv::Size size;
  int id;
  int search_decimate = 2;
  bool small_markers = false;  // marker_bench --min-side 16 --quiet-cells 1
};

// Whether the search with `passes` reads the case's marker; never a wrong id or a false positive.
bool searchReads(const ReadCase& c, const SearchPasses& passes = {}) {
  DetectorConfig config;
  config.search_decimate = c.search_decimate;
  config.passes = passes;
  test::LayoutOptions options;
  const float scale = static_cast<float>(c.size.width) / 640.0f;
  options.size = c.size;
  options.min_side_px = (c.small_markers ? 16.0f : 48.0f) * scale;
  options.max_side_px = 110.0f * scale;
  options.quiet_cells = c.small_markers ? 1.0f : 2.0f;
  options.tilt_from = test::LayoutOptions::TiltFrom::LineOfSight;
  const test::RenderedScene scene = test::renderScene(test::makeLayout(options, c.seed),
                                                      test::MarkerFamily::ArbciBch, c.condition);
  std::vector<test::FoundMarker> found;
  bool read = false;
  for (const MarkerDetection& m : MarkerDetector(config).detect(scene.image).markers) {
    found.push_back({m.id, m.corners});
    read = read || m.id == c.id;
  }
  const test::Score score = test::scoreFrame(scene.ids, scene.markers, found, /*ordered=*/true);
  EXPECT_EQ(score.wrong_id, 0) << "seed " << c.seed;
  EXPECT_EQ(score.false_positive, 0) << "seed " << c.seed;
  return read;
}

void expectSearchReads(const ReadCase& c) {
  EXPECT_TRUE(searchReads(c)) << "seed " << c.seed << ", id " << c.id;
}

// Motion blur can leave a marker's two ends as separate groups of fragments, whose boxes overlap
// but whose pieces are too far apart to be grouped (the smear greyed the border between them);
// such a pair is also tried as one region. Each of these markers was missed by the decimated
// search before that, with no other marker of its frame lost: seed 9928's at 1280x720 under
// motion blur (its top and bottom border greyed by a vertical smear), and three at 640x480.
TEST(SyntheticScenes, DecimatedSearchTriesOverlappingFragmentGroupsAsOneRegion) {
  for (const ReadCase& c : {ReadCase{9928u, Condition::MotionBlur, {1280, 720}, 1639},
                            ReadCase{9064u, Condition::MotionBlurJpeg, {640, 480}, 1391},
                            ReadCase{9086u, Condition::FastMotionJpeg, {640, 480}, 3154},
                            ReadCase{10084u, Condition::MotionBlur, {640, 480}, 3054}})
    expectSearchReads(c);
}

// A smear across a marker's border can cut the marker in two: one end a quad of its own that
// does not decode, the other a near miss. The near miss is binarised again together with the
// quads it partly overlaps; around it alone, the marker was cut off at the region's edge. These
// markers were missed before that: seed 9000's at 1280x720 under motion+JPEG (61 x 99 px, smeared
// along its long sides), and two at 640x480 under motion blur.
TEST(SyntheticScenes, DecimatedSearchRetriesANearMissWithTheQuadsItOverlaps) {
  for (const ReadCase& c : {ReadCase{9000u, Condition::MotionBlurJpeg, {1280, 720}, 3182},
                            ReadCase{9055u, Condition::MotionBlur, {640, 480}, 3178},
                            ReadCase{10094u, Condition::MotionBlur, {640, 480}, 3737}})
    expectSearchReads(c);
}

// The full search tries a region that gave no quad once more at one threshold, halfway between
// its darkest and lightest grey, when these span nearly the frame's range. Smeared by 5-15 px,
// these markers of the small-marker scenes (a 1-cell quiet zone) were missed before that: the
// edge tiles' thresholds followed the grey background and joined the greyed border to it.
TEST(SyntheticScenes, FullSearchReadsSmearedMarkersAtTheirRegionsMidGrey) {
  const auto smallMarker = [](std::uint32_t seed, Condition condition, int id) {
    return ReadCase{.seed = seed,
                    .condition = condition,
                    .size = {640, 480},
                    .id = id,
                    .search_decimate = 1,
                    .small_markers = true};
  };
  const std::vector<ReadCase> cases{smallMarker(1025u, Condition::MotionBlur, 2074),
                                    smallMarker(1053u, Condition::MotionBlur, 3866),
                                    smallMarker(1050u, Condition::MotionBlur, 9),
                                    smallMarker(1007u, Condition::MotionBlurJpeg, 1576),
                                    smallMarker(1014u, Condition::FastMotionJpeg, 1867)};
  for (const ReadCase& c : cases) expectSearchReads(c);
  // The pass is a setting (tracker.passes.mid_grey): switched off, these markers are missed by
  // the outline search (the edge-segment pass, which needs no outline, reads some of them).
  SearchPasses without;
  without.mid_grey.enabled = false;
  without.edge_segments.enabled = false;
  int read_without = 0;
  for (const ReadCase& c : cases) read_without += searchReads(c, without);
  EXPECT_LE(read_without, 1);
}

// A marker smeared by motion blur whose sharpened reading lay 2 bits from another id's codeword
// was read as that id (2182 as 2939) when every extra reading could correct 2 bits; the extra
// readings now correct 1, and Chase decoding judges the rest by the cells' reliability.
TEST(SyntheticScenes, ASmearedMarkersExtraReadingDoesNotMakeItAnotherId) {
  EXPECT_TRUE(searchReads(ReadCase{.seed = 41004u,
                                   .condition = Condition::MotionBlur,
                                   .size = {640, 480},
                                   .id = 3097,
                                   .search_decimate = 1}));
}

// The angle between a posed square's normal and the line of sight to its centre, degrees, from
// its four projected corners alone: the homography of the square (-1,-1)..(-1,1) onto them is
// K [r1 r2 t] up to scale for the scenes' camera K (focal length 0.9 of the width, principal
// point at the centre), so the plane's normal is r1 x r2 and its centre lies along t.
double viewAngleDeg(const test::Corners& corners, cv::Size size) {
  const std::vector<cv::Point2f> square{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  const std::vector<cv::Point2f> image(corners.begin(), corners.end());
  const cv::Matx33d h(cv::getPerspectiveTransform(square, image));
  const double f = 0.9 * size.width;
  const cv::Matx33d k(f, 0, 0.5 * size.width, 0, f, 0.5 * size.height, 0, 0, 1);
  const cv::Matx33d m = k.inv() * h;
  const cv::Vec3d r1(m(0, 0), m(1, 0), m(2, 0)), r2(m(0, 1), m(1, 1), m(2, 1)),
      t(m(0, 2), m(1, 2), m(2, 2));
  const cv::Vec3d normal = r1.cross(r2);
  return std::acos(std::abs(normal.dot(t)) / (cv::norm(normal) * cv::norm(t))) * 180.0 / CV_PI;
}

// The benchmark's scenes tilt markers from the line of sight: none is seen more obliquely than
// the tilt asked for. Tilted from the optical axis instead (the scenes before 2026-11-26), markers
// near the frame's sides were seen up to the tilt plus their ray's angle off face-on, nearly
// edge-on: AprilTag at decimate 2 missed 10-11 of 300 such clean markers on some seed sets.
TEST(SyntheticScenes, LayoutsTiltedFromTheLineOfSightAreSeenNoMoreObliquelyThanTheTilt) {
  for (const auto tilt_from :
       {test::LayoutOptions::TiltFrom::LineOfSight, test::LayoutOptions::TiltFrom::OpticalAxis}) {
    test::LayoutOptions options;
    options.min_side_px = 48.0f;
    options.quiet_cells = 2.0f;
    options.tilt_from = tilt_from;
    double most_oblique = 0.0;
    int markers = 0;
    for (std::uint32_t seed = 9000; seed < 9200; ++seed) {
      const test::SceneLayout layout = test::makeLayout(options, seed);
      for (const test::Corners& marker : layout.markers) {
        most_oblique = std::max(most_oblique, viewAngleDeg(marker, layout.size));
        ++markers;
      }
    }
    EXPECT_EQ(markers, 600);
    if (tilt_from == test::LayoutOptions::TiltFrom::LineOfSight) {
      EXPECT_LE(most_oblique, options.max_tilt_deg + 0.05);
      EXPECT_GE(most_oblique, options.max_tilt_deg - 1.0);  // the tilts still reach the limit
    } else {
      EXPECT_GE(most_oblique, options.max_tilt_deg + 20.0);
    }
  }
}

TEST(SyntheticScenes, MarkerFreeFramesGiveNoDetections) {
  MarkerDetector detector(DetectorConfig{});
  for (Condition condition : {Condition::Clean, Condition::Blur, Condition::Noise,
                              Condition::UnevenLight, Condition::Combined}) {
    for (int f = 0; f < 15; ++f) {
      test::LayoutOptions options;
      options.decoys = 5;
      const test::SceneLayout layout = test::makeLayout(options, 9000u + static_cast<unsigned>(f));
      EXPECT_TRUE(detector.detect(test::renderMarkerFree(layout, condition)).markers.empty())
          << test::toString(condition) << " frame " << f;
    }
  }
}

// Two decoys of the benchmark's marker-free frames that a quad placed on blurred edges once read
// as markers through Chase decoding (id 57, 5 cells overruled; id 2940, 3): such quads are read
// again without it.
TEST(SyntheticScenes, DecoysPlacedOnBlurredEdgesAreNotReadAsMarkers) {
  test::LayoutOptions fair;
  fair.min_side_px = 48.0f;
  fair.quiet_cells = 2.0f;
  struct Case {
    std::uint32_t seed;
    Condition condition;
    int decimate;
  };
  for (const Case& c :
       {Case{9600u, Condition::MotionBlur, 1}, Case{1044u, Condition::Combined, 2}}) {
    DetectorConfig config;
    config.search_decimate = c.decimate;
    const cv::Mat frame = test::renderMarkerFree(test::makeLayout(fair, c.seed), c.condition);
    EXPECT_TRUE(MarkerDetector(config).detect(frame).markers.empty()) << "seed " << c.seed;
  }
}

// A corner cut off (a chamfer, a dog-eared print) within 0.3 of a side of the corner leaves the
// outline a quad, its corner where the sides meet; a notch in the middle of a side does not.
TEST(SyntheticScenes, AMarkerWithACornerCutOffIsReadWhereItsSidesMeet) {
  MarkerDetector detector(DetectorConfig{});
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(160));
  const int id = 1234;
  const test::Corners quad{{{100.0f, 60.0f}, {200.0f, 60.0f}, {200.0f, 160.0f}, {100.0f, 160.0f}}};
  const test::Corners outer{{{87.5f, 47.5f}, {212.5f, 47.5f}, {212.5f, 172.5f}, {87.5f, 172.5f}}};
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, id, 8), outer);
  // Legs of 10 px, inside the border's corner cell (12.5 px). A corner is taken at one end of
  // the cut, so the side that skips the cut strays from its chord by up to 9 px, more than the
  // 8 px a 100 px side may, but by less farther than 30 px from that corner.
  const std::vector<cv::Point> cut{{100, 60}, {110, 60}, {100, 70}};
  cv::fillConvexPoly(frame, cut, cv::Scalar(255));
  const auto markers = detector.detect(frame).markers;
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].id, id);
  for (int k = 0; k < 4; ++k)
    EXPECT_LT(cv::norm(markers[0].corners[k] - quad[k]), 1.0) << "corner " << k;
}

TEST(SyntheticScenes, ASquareRingNotchedMidSideIsNoSquare) {
  MarkerDetector detector(DetectorConfig{});
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(160));
  cv::rectangle(frame, cv::Rect(80, 50, 140, 140), cv::Scalar(255), cv::FILLED);  // surround
  cv::rectangle(frame, cv::Rect(100, 70, 100, 100), cv::Scalar(0), cv::FILLED);
  cv::rectangle(frame, cv::Rect(115, 85, 70, 70), cv::Scalar(255), cv::FILLED);
  // 10 px deep and 12 wide in the middle of the top side, 44 px from either corner.
  cv::rectangle(frame, cv::Rect(144, 70, 12, 10), cv::Scalar(255), cv::FILLED);
  detector.detect(frame);
  EXPECT_TRUE(detector.lastSquares().empty());
  // Without the notch the ring is a square.
  cv::rectangle(frame, cv::Rect(144, 70, 12, 10), cv::Scalar(0), cv::FILLED);
  detector.detect(frame);
  EXPECT_EQ(detector.lastSquares().size(), 1u);
}

TEST(SyntheticScenes, AMarkerIsReadAtGivenCornersInEitherTurnAndABlankSquareIsNot) {
  MarkerDetector detector(DetectorConfig{});
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(160));
  const int id = 2345;
  // An 80 px square turned 20 degrees; its white margin a cell (a tenth of the drawn image) wide.
  const cv::Point2f centre(160.0f, 110.0f);
  const float c = 40.0f * std::cos(0.35f), d = 40.0f * std::sin(0.35f);
  const test::Corners quad{{centre + cv::Point2f(-c + d, -d - c),
                            centre + cv::Point2f(c + d, d - c), centre + cv::Point2f(c - d, d + c),
                            centre + cv::Point2f(-c - d, -d + c)}};
  test::Corners outer;
  for (int k = 0; k < 4; ++k) outer[k] = centre + 1.25f * (quad[k] - centre);
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, id, 8), outer);
  const auto read = detector.readAt(frame, quad);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->id, id);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(read->corners[k], quad[k]) << "corner " << k;
  // Counter-clockwise, starting elsewhere: the same marker, its corners in the printed order.
  const auto turned = detector.readAt(frame, {quad[1], quad[0], quad[3], quad[2]});
  ASSERT_TRUE(turned.has_value());
  EXPECT_EQ(turned->id, id);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(turned->corners[k], quad[k]) << "corner " << k;
  // Where there is no marker, nothing.
  EXPECT_FALSE(
      detector
          .readAt(frame, {{{230.0f, 150.0f}, {300.0f, 150.0f}, {300.0f, 220.0f}, {230.0f, 220.0f}}})
          .has_value());
  DetectorConfig aruco;
  aruco.kind = MarkerKind::Aruco;
  MarkerDetector dictionary(aruco);
  EXPECT_THROW(dictionary.readAt(frame, quad), std::invalid_argument);
}

TEST(SyntheticScenes, CornersComeInThePrintedOrder) {
  // A marker rotated in the image still reports its printed top-left first.
  MarkerDetector detector(DetectorConfig{});
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(160));
  const int id = 1234;
  const test::Corners quad{
      {{200.0f, 60.0f}, {200.0f, 160.0f}, {100.0f, 160.0f}, {100.0f, 60.0f}}};  // turned 90 deg
  const test::Corners outer{{{212.5f, 47.5f}, {212.5f, 172.5f}, {87.5f, 172.5f}, {87.5f, 47.5f}}};
  test::drawWarped(frame, test::markerImage(test::MarkerFamily::ArbciBch, id, 8), outer);
  const auto markers = detector.detect(frame).markers;
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].id, id);
  for (int k = 0; k < 4; ++k)
    EXPECT_LT(cv::norm(markers[0].corners[k] - quad[k]), 0.2) << "corner " << k;
}

}  // namespace
}  // namespace arbci::vision
