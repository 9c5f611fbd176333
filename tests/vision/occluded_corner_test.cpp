// A marker with one corner covered (a gripper's finger or a hand during a grasp), beside
// libapriltag (decimate 2) on the same scenes drawn with its own tags: discs of 15-25 % of the
// side, dark and light, over a corner, on scenes (seeds 9000-9099) that the recovery was not
// developed on (5000-5059). The tracker must find at least as many as the peer, dark or light, and
// never a wrong id.
#include <gtest/gtest.h>

#include <cstdio>

#include "arbci/vision/marker_detector.h"
#include "support/marker_scoring.h"
#include "support/occluded_markers.h"

namespace arbci::test {
namespace {

constexpr int kArbciId = 1234, kAprilTagId = 123;

struct Tally {
  int found = 0, wrong = 0, frames = 0;
};

Tally count(MarkerFamily family, int id, const vision::DetectorConfig& config, Occluder occluder,
            unsigned first_seed, int frames) {
  vision::MarkerDetector detector(config);
  Tally t;
  for (int i = 0; i < frames; ++i) {
    const OccludedFrame f = occludedMarkerFrame(family, id, occluder, 0.15, 0.25,
                                                first_seed + static_cast<unsigned>(i));
    std::vector<FoundMarker> found;
    for (const vision::MarkerDetection& m : detector.detect(f.image).markers) {
      FoundMarker fm;
      fm.id = m.id;
      fm.corners = m.corners;
      found.push_back(fm);
    }
    const Score s = scoreFrame({id}, {f.truth}, found, true);
    t.found += s.found;
    t.wrong += s.wrong_id;
    ++t.frames;
  }
  return t;
}

// `search` against libapriltag (decimate 2), both discs, on scenes 9000-9099: at least as many
// found and no wrong id.
void expectAtLeastAprilTag(const vision::DetectorConfig& search, const char* name) {
  vision::DetectorConfig apriltag;
  apriltag.kind = vision::MarkerKind::AprilTag;
  apriltag.search_decimate = 2;
  for (const Occluder occluder : {Occluder::Dark, Occluder::Light}) {
    const char* disc = occluder == Occluder::Dark ? "dark" : "light";
    const Tally ours = count(MarkerFamily::ArbciBch, kArbciId, search, occluder, 9000, 100);
    const Tally peer =
        count(MarkerFamily::AprilTag36h11, kAprilTagId, apriltag, occluder, 9000, 100);
    // bench/occlusion_bench prints these figures for every run.
    const std::string figures = std::string(disc) + " disc: " + name + " " +
                                std::to_string(ours.found) + "/" + std::to_string(ours.frames) +
                                " (" + std::to_string(ours.wrong) + " wrong), AprilTag " +
                                std::to_string(peer.found) + "/" + std::to_string(peer.frames);
    EXPECT_EQ(ours.wrong, 0) << figures;
    EXPECT_GE(ours.found, peer.found) << figures;
  }
}

TEST(OccludedCorner, AMarkerWithACornerCoveredIsFoundBesideAprilTagAndNeverMisread) {
  expectAtLeastAprilTag(vision::DetectorConfig{}, "ARBCI");  // the session's defaults
}

// The decimated search fits a covered outline on the reduced image and moves it onto the frame:
// the quad must still be read as one whose border may show the cover (a light disc over the
// corner leaves light where the border was).
TEST(OccludedCorner, TheDecimatedSearchReadsACoveredMarkerToo) {
  vision::DetectorConfig decimated;
  decimated.search_decimate = 2;
  expectAtLeastAprilTag(decimated, "ARBCI (decimate 2)");
}

}  // namespace
}  // namespace arbci::test
