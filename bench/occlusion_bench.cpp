// A marker with one corner covered (a finger or the gripper during a grasp): the tracker beside
// libapriltag and OpenCV ArUco on the same scenes, each drawn with its own marker. One marker per
// 640x480 frame at a random pose, a disc over one corner, dark or light, its radius a random
// fraction of the side in [--min-radius, --max-radius]. Prints found, wrong ids and time.
//   occlusion_bench [--frames N] [--first-seed S]   (--help explains)
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "marker_peers.h"
#include "support/occluded_markers.h"

using namespace arbci;

namespace {

// The id each family draws: any readable one (the scenes do not depend on it).
int markerId(test::MarkerFamily family) {
  return family == test::MarkerFamily::ArbciBch ? 1234 : 123;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"A marker with a corner covered: the ARBCI tracker beside AprilTag 3 and ArUco"};
  int frames = 100;
  unsigned first_seed = 30000;
  double min_radius = 0.15, max_radius = 0.25;
  cli.add_option("--frames", frames, "scenes per occluder")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cli.add_option("--first-seed", first_seed,
                 "seed of the first scene (scene f uses first-seed + f); the tracker's occluded-"
                 "corner pass was developed on 5000-5059 and is tested on 9000-9099")
      ->capture_default_str();
  cli.add_option("--min-radius", min_radius, "smallest disc radius, fraction of the side")
      ->check(CLI::Range(0.01, 0.5))
      ->capture_default_str();
  cli.add_option("--max-radius", max_radius, "largest disc radius, fraction of the side")
      ->check(CLI::Range(0.01, 0.5))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  if (max_radius < min_radius) {
    std::fprintf(stderr, "occlusion_bench: --max-radius is below --min-radius\n");
    return 2;
  }
  const auto detectors = bench::detectorsUnderTest();
  std::printf(
      "One marker per 640x480 scene (seeds %u-%u), a disc of %.0f-%.0f %% of the side over a "
      "corner.\n%-32s %-6s %9s %6s %9s\n",
      first_seed, first_seed + static_cast<unsigned>(frames) - 1, 100.0 * min_radius,
      100.0 * max_radius, "detector", "disc", "found", "wrong", "ms/frame");
  for (const test::Occluder occluder : {test::Occluder::Dark, test::Occluder::Light}) {
    for (const auto& detector : detectors) {
      const int id = markerId(detector->family());
      int found = 0, wrong = 0, with_square = 0, readable = 0;
      double seconds = 0.0;
      for (int f = 0; f < frames; ++f) {
        const test::OccludedFrame scene =
            test::occludedMarkerFrame(detector->family(), id, occluder, min_radius, max_radius,
                                      first_seed + static_cast<unsigned>(f));
        const auto start = std::chrono::steady_clock::now();
        const std::vector<test::FoundMarker> seen = detector->detect(scene.image);
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const test::Score s =
            test::scoreFrame({id}, {scene.truth}, seen, detector->orderedCorners());
        found += s.found;
        wrong += s.wrong_id;
        if (s.found == 0) {
          if (const auto miss = detector->explainMiss(scene.image, scene.truth, id)) {
            with_square += miss->square_on_it;
            readable += miss->readable_at_truth;
          }
        }
      }
      std::printf("%-32s %-6s %5d/%-3d %6d %9.3f", detector->name().c_str(),
                  occluder == test::Occluder::Dark ? "dark" : "light", found, frames, wrong,
                  1000.0 * seconds / frames);
      // The tracker's misses: a square found on the marker, or its code readable at the true
      // corners (then the search, not the reading, lost it).
      if (detector->family() == test::MarkerFamily::ArbciBch)
        std::printf("   misses: %d with a square on it, %d readable at the true corners",
                    with_square, readable);
      std::printf("\n");
    }
  }
  return 0;
}
