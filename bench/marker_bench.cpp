// Marker detection: recall, wrong IDs, false positives, corner error and time per frame of the
// ARBCI tracker beside AprilTag 3 and OpenCV ArUco, on the same synthetic scenes (each drawn with
// the detector's own markers) under seven conditions (five photometric, two motion blurs), at
// 640x480 and 1280x720.
//   marker_bench [--frames N] [--sizes 640x480,1280x720]   (--help explains)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "marker_peers.h"

using namespace arbci;

namespace {

struct Cell {
  test::Score score;
  double seconds = 0.0;
  int frames = 0;
  int marker_free_false_positives = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "Marker detection of the ARBCI tracker beside AprilTag 3 and OpenCV ArUco on synthetic "
      "scenes with exact truth"};
  int frames = 40;
  std::vector<std::string> size_names{"640x480", "1280x720"};
  cli.add_option("--frames", frames, "frames per condition and size")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cli.add_option("--sizes", size_names, "frame sizes, WxH")->delimiter(',')->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  std::vector<cv::Size> sizes;
  for (const std::string& name : size_names) {
    int w = 0, h = 0;
    if (std::sscanf(name.c_str(), "%dx%d", &w, &h) != 2 || w < 160 || h < 120) {
      std::fprintf(stderr, "marker_bench: --sizes: '%s' is not a size WxH of at least 160x120\n",
                   name.c_str());
      return 2;
    }
    sizes.emplace_back(w, h);
  }
  std::vector<std::unique_ptr<bench::MarkerDetectorUnderTest>> detectors;
  detectors.push_back(bench::makeArbciTracker());
  detectors.push_back(bench::makeAprilTag(2.0f));
  detectors.push_back(bench::makeAprilTag(1.0f));
  detectors.push_back(bench::makeAruco());
  const std::vector<test::Condition> conditions{
      test::Condition::Clean,         test::Condition::Blur,     test::Condition::Noise,
      test::Condition::UnevenLight,   test::Condition::Combined, test::Condition::MotionBlur,
      test::Condition::MotionBlurJpeg};
  std::printf(
      "Marker detection, %d frames per condition, 3 markers (20-110 px, tilt <= 60 deg) and 2 "
      "decoys "
      "per frame;\nthe same layouts drawn with each detector's markers. Time: mean per frame, one "
      "core.\n",
      frames);
  for (const cv::Size size : sizes) {
    std::map<std::pair<int, int>, Cell> cells;  // (detector, condition)
    for (int f = 0; f < frames; ++f) {
      test::LayoutOptions options;
      options.size = size;
      options.max_side_px = 110.0f * size.width / 640.0f;
      const test::SceneLayout layout = test::makeLayout(options, 1000u + static_cast<unsigned>(f));
      for (size_t c = 0; c < conditions.size(); ++c) {
        const cv::Mat marker_free = test::renderMarkerFree(layout, conditions[c]);
        for (size_t d = 0; d < detectors.size(); ++d) {
          const test::RenderedScene scene =
              test::renderScene(layout, detectors[d]->family(), conditions[c]);
          const auto start = std::chrono::steady_clock::now();
          const std::vector<test::FoundMarker> found = detectors[d]->detect(scene.image);
          const double seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
          cell.score.add(
              test::scoreFrame(scene.ids, scene.markers, found, detectors[d]->orderedCorners()));
          cell.seconds += seconds;
          ++cell.frames;
          cell.marker_free_false_positives +=
              static_cast<int>(detectors[d]->detect(marker_free).size());
        }
      }
    }
    std::printf("\n%dx%d\n%-30s %-13s %7s %6s %6s %9s %10s %9s\n", size.width, size.height,
                "detector", "condition", "recall", "wrong", "false+", "corner px", "ms/frame",
                "empty fp");
    std::vector<double> mean_ms(detectors.size(), 0.0);
    for (size_t d = 0; d < detectors.size(); ++d) {
      for (size_t c = 0; c < conditions.size(); ++c) {
        const Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
        const double ms = 1000.0 * cell.seconds / cell.frames;
        mean_ms[d] += ms / static_cast<double>(conditions.size());
        std::printf("%-30s %-13s %7.3f %6d %6d %9.3f %10.3f %9d\n", detectors[d]->name().c_str(),
                    test::toString(conditions[c]).c_str(), cell.score.recall(), cell.score.wrong_id,
                    cell.score.false_positive, cell.score.meanCornerError(), ms,
                    cell.marker_free_false_positives);
      }
    }
    std::printf("\nmean time per frame over the %zu conditions, %dx%d:\n", conditions.size(),
                size.width, size.height);
    const double fastest_peer = *std::min_element(mean_ms.begin() + 1, mean_ms.end());
    for (size_t d = 0; d < detectors.size(); ++d) {
      std::printf("  %-30s %8.3f ms  (%.2fx the fastest peer)\n", detectors[d]->name().c_str(),
                  mean_ms[d], mean_ms[d] / fastest_peer);
    }
    std::printf("recall by condition, ARBCI vs the best peer:\n");
    for (size_t c = 0; c < conditions.size(); ++c) {
      double best_peer = 0.0;
      for (size_t d = 1; d < detectors.size(); ++d) {
        best_peer =
            std::max(best_peer, cells[{static_cast<int>(d), static_cast<int>(c)}].score.recall());
      }
      const double ours = cells[{0, static_cast<int>(c)}].score.recall();
      std::printf("  %-13s ARBCI %.3f  best peer %.3f  %s\n", test::toString(conditions[c]).c_str(),
                  ours, best_peer, ours >= best_peer ? "ok" : "BELOW");
    }
  }
  return 0;
}
