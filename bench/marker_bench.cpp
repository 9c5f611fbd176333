// Marker detection: recall, wrong IDs, false positives, corner error and time per frame of the
// ARBCI tracker beside AprilTag 3 and OpenCV ArUco, on the same synthetic scenes (each drawn with
// the detector's own markers) under eight conditions (five photometric, three motion blurs), at
// 640x480 and 1280x720. By default the scenes are fair to every peer: markers printed with a
// 2-cell white margin and no smaller than 48 px at 640x480 (each peer reads at least 0.97 of them
// on clean frames); --min-side 16 --quiet-cells 1 gives the small-marker scenes.
//   marker_bench [--frames N] [--sizes 640x480,1280x720]   (--help explains)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "arbci/vision/settings.h"
#include "marker_peers.h"

using namespace arbci;

namespace {

// Apparent marker sides the recall is broken down by (px, the mean of the four sides).
constexpr double kSideBins[] = {0.0, 30.0, 45.0, 60.0, 80.0};
constexpr int kSideBinCount = 5;
// The speed target of the tracker's search against the fastest peer (issue 43: at most half its
// time in every condition).
constexpr double kTargetTimeRatio = 0.5;

int sideBin(const test::Corners& q) {
  double side = 0.0;
  for (int k = 0; k < 4; ++k) side += cv::norm(q[k] - q[(k + 1) % 4]) / 4.0;
  int bin = 0;
  while (bin + 1 < kSideBinCount && side >= kSideBins[bin + 1]) ++bin;
  return bin;
}

struct Cell {
  test::Score score;
  int truth_by_side[kSideBinCount] = {};
  int found_by_side[kSideBinCount] = {};
  double seconds = 0.0;
  int frames = 0;
  int marker_free_false_positives = 0;
  vision::StageTimes stages;  // summed over the frames (detectors that measure them)
  // Misses, for the detectors that explain them (ARBCI's own).
  int missed = 0, missed_with_square = 0, missed_readable = 0;
};

// The photographs in `dir` (PNG and JPEG, by name), for the cluttered condition's backgrounds.
std::vector<cv::Mat> loadPhotos(const std::string& dir) {
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") paths.push_back(entry.path());
  }
  std::sort(paths.begin(), paths.end());
  std::vector<cv::Mat> photos;
  for (const auto& path : paths) {
    cv::Mat photo = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
    if (!photo.empty()) photos.push_back(photo);
  }
  return photos;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "Marker detection of the ARBCI tracker beside AprilTag 3 and OpenCV ArUco on synthetic "
      "scenes with exact truth"};
  cli.footer(
      "Conditions (each a row of every table):\n"
      "  clean          the scene as drawn (anti-aliased by 4x supersampling)\n"
      "  blur           Gaussian blur, sigma 1.5 px (a soft focus)\n"
      "  noise          Gaussian noise, SD 12 grey levels (a dim sensor)\n"
      "  uneven light   a gain of 0.15-1: a gradient, a vignette and a soft shadow band\n"
      "  combined       uneven light, then the blur, then the noise\n"
      "  motion blur    a linear kernel 5-15 px long at a random angle (a head turning)\n"
      "  motion+JPEG    the motion blur, then JPEG at quality 50 (a compressing camera)\n"
      "  fast motion+J  a 9-15 px kernel (a faster turn), then JPEG at quality 50\n"
      "  cluttered      the scene over a photograph instead of the synthetic table (natural\n"
      "                 texture: give --backgrounds DIR; a random crop, 1-1.5x the size that\n"
      "                 covers the frame, of one photo per frame)\n"
      "Each scene also has a marker-free frame of the same condition (false positives).");
  int frames = 40;
  std::vector<std::string> size_names{"640x480", "1280x720"};
  cli.add_option("--frames", frames, "frames per condition and size")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cli.add_option("--sizes", size_names, "frame sizes, WxH")->delimiter(',')->capture_default_str();
  int quiet_cells = 2;
  cli.add_option("--quiet-cells", quiet_cells, "white margin printed around every marker, cells")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  float min_side_px = 48.0f;
  float max_side_px = 110.0f;
  cli.add_option("--min-side", min_side_px,
                 "face-on side of the smallest marker at 640x480, px (scaled with the width)")
      ->check(CLI::Range(8.0f, 100.0f))
      ->capture_default_str();
  cli.add_option("--max-side", max_side_px,
                 "face-on side of the largest marker at 640x480, px (scaled with the width)")
      ->check(CLI::Range(8.0f, 400.0f))
      ->capture_default_str();
  unsigned first_seed = 1000;
  cli.add_option("--first-seed", first_seed,
                 "seed of the first frame's layout (frame f uses first-seed + f); other seeds give "
                 "scenes nothing was tuned on")
      ->capture_default_str();
  float max_tilt_deg = 60.0f;
  cli.add_option("--max-tilt", max_tilt_deg, "largest tilt of a marker off face-on, degrees")
      ->check(CLI::Range(0.0f, 85.0f))
      ->capture_default_str();
  std::string tilt_from_name = "sight";
  cli.add_option("--tilt-from", tilt_from_name,
                 "what the tilt is measured from: 'sight', the line of sight to the marker (no "
                 "marker is seen more obliquely than --max-tilt), or 'axis', the camera's optical "
                 "axis (markers near the frame's sides are then seen up to about 30 deg more "
                 "obliquely, nearly edge-on at the largest tilts; the scenes of this bench "
                 "before 2026-11-26)")
      ->check(CLI::IsMember({"sight", "axis"}))
      ->capture_default_str();
  bool by_side = false;
  cli.add_flag("--by-side", by_side,
               "also print recall by apparent marker side (<30, 30-45, 45-60, 60-80, >=80 px)");
  std::string backgrounds;
  cli.add_option("--backgrounds", backgrounds,
                 "a folder of photographs (PNG, JPEG) for the cluttered condition; without it that "
                 "condition is left out")
      ->check(CLI::ExistingDirectory);
  std::string detections_path;
  cli.add_option("--detections", detections_path,
                 "write every ARBCI detection (size, seed, condition, detector, id, corners) to "
                 "this file, one per line: two builds that should detect the same compare by diff");
  // The passes that can be switched off: the sections of the settings schema's tracker.passes.
  std::vector<std::string> pass_names;
  for (const core::Key& key : vision::searchPassesSchema().keys())
    if (key.type == core::Type::Section) pass_names.push_back(key.name);
  std::vector<std::string> passes_off;
  cli.add_option(
         "--without", passes_off,
         "ARBCI's search without these passes (tracker.passes: " +
             [&] {
               std::string list;
               for (const std::string& n : pass_names) list += (list.empty() ? "" : ", ") + n;
               return list;
             }() +
             "), to measure what each catches and costs")
      ->delimiter(',')
      ->check(CLI::IsMember(pass_names));
  bool peers = true;
  cli.add_flag("!--no-peers", peers, "run ARBCI's searches alone (no AprilTag, no ArUco)");
  std::string examples_dir;
  cli.add_option("--examples", examples_dir,
                 "write the first frame of every condition and size, as ARBCI's markers are drawn, "
                 "to this folder (PNG) to look at")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(cli, argc, argv);
  std::vector<cv::Mat> photos;
  if (!backgrounds.empty()) {
    photos = loadPhotos(backgrounds);
    if (photos.empty()) {
      std::fprintf(stderr, "marker_bench: --backgrounds: no PNG or JPEG photograph in '%s'\n",
                   backgrounds.c_str());
      return 2;
    }
  }
  FILE* detections = nullptr;
  if (!detections_path.empty()) {
    detections = std::fopen(detections_path.c_str(), "w");
    if (!detections) {
      std::fprintf(stderr, "marker_bench: --detections: cannot write '%s'\n",
                   detections_path.c_str());
      return 2;
    }
  }
  const auto tilt_from = tilt_from_name == "sight" ? test::LayoutOptions::TiltFrom::LineOfSight
                                                   : test::LayoutOptions::TiltFrom::OpticalAxis;
  if (max_side_px < min_side_px) {
    std::fprintf(stderr, "marker_bench: --max-side (%g) is below --min-side (%g)\n", max_side_px,
                 min_side_px);
    return 2;
  }
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
  vision::SearchPasses passes;
  nlohmann::json pass_settings = vision::searchPassesSchema().write(passes);
  for (const std::string& pass : passes_off) pass_settings[pass]["enabled"] = false;
  vision::searchPassesSchema().read(pass_settings, passes);
  const auto detectors = bench::detectorsUnderTest(passes, peers);
  const size_t ours = 2;  // ARBCI's searches come first, then the peers
  std::vector<test::Condition> conditions{
      test::Condition::Clean,          test::Condition::Blur,          test::Condition::Noise,
      test::Condition::UnevenLight,    test::Condition::Combined,      test::Condition::MotionBlur,
      test::Condition::MotionBlurJpeg, test::Condition::FastMotionJpeg};
  if (!photos.empty()) conditions.push_back(test::Condition::Cluttered);
  std::printf(
      "Marker detection, %d frames per condition (layout seeds %u-%u), 3 markers (%g-%g px at "
      "640x480, scaled with the width; tilt <= %g deg from the %s; %d-cell white margin) and 2 "
      "decoys per frame;\nthe same layouts drawn with each detector's markers. Time: mean per "
      "frame, one core.\n",
      frames, first_seed, first_seed + static_cast<unsigned>(frames) - 1, min_side_px, max_side_px,
      max_tilt_deg,
      tilt_from == test::LayoutOptions::TiltFrom::LineOfSight ? "line of sight" : "optical axis",
      quiet_cells);
  if (!passes_off.empty()) {
    std::printf("ARBCI's searches without the passes:");
    for (const std::string& pass : passes_off) std::printf(" %s", pass.c_str());
    std::printf("\n");
  }
  if (photos.empty())
    std::printf("(the cluttered condition is left out: give --backgrounds DIR of photographs)\n");
  else
    std::printf("cluttered: %zu photographs from %s\n", photos.size(), backgrounds.c_str());
  for (const cv::Size size : sizes) {
    std::map<std::pair<int, int>, Cell> cells;  // (detector, condition)
    for (int f = 0; f < frames; ++f) {
      test::LayoutOptions options;
      options.size = size;
      options.max_side_px = max_side_px * size.width / 640.0f;
      options.quiet_cells = static_cast<float>(quiet_cells);
      options.min_side_px = min_side_px * size.width / 640.0f;
      options.max_tilt_deg = max_tilt_deg;
      options.tilt_from = tilt_from;
      const unsigned seed = first_seed + static_cast<unsigned>(f);
      test::SceneLayout layout = test::makeLayout(options, seed);
      if (!photos.empty()) layout.backdrop = test::backdropFromPhotos(photos, size, seed);
      for (size_t c = 0; c < conditions.size(); ++c) {
        const cv::Mat marker_free = test::renderMarkerFree(layout, conditions[c]);
        for (size_t d = 0; d < detectors.size(); ++d) {
          const test::RenderedScene scene =
              test::renderScene(layout, detectors[d]->family(), conditions[c]);
          const auto start = std::chrono::steady_clock::now();
          const std::vector<test::FoundMarker> found = detectors[d]->detect(scene.image);
          const double seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (detections && d < ours) {
            for (const test::FoundMarker& m : found) {
              std::fprintf(detections, "%dx%d %u %s %s %d", size.width, size.height, seed,
                           test::toString(conditions[c]).c_str(), detectors[d]->name().c_str(),
                           m.id);
              for (const cv::Point2f& p : m.corners)
                std::fprintf(detections, " %.3f %.3f", p.x, p.y);
              std::fprintf(detections, "\n");
            }
          }
          if (!examples_dir.empty() && f == 0 && d == 0) {
            std::string name = test::toString(conditions[c]);
            std::replace_if(
                name.begin(), name.end(), [](char ch) { return !std::isalnum(ch); }, '-');
            cv::imwrite(examples_dir + "/" + std::to_string(size.width) + "x" +
                            std::to_string(size.height) + "-" + name + ".png",
                        scene.image);
          }
          Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
          const test::Score frame_score =
              test::scoreFrame(scene.ids, scene.markers, found, detectors[d]->orderedCorners());
          cell.score.add(frame_score);
          if (frame_score.wrong_id > 0 || frame_score.false_positive > 0) {
            // Named, so that a wrong reading can be looked at (--examples draws the frame).
            std::fprintf(stderr, "%s: %dx%d seed %u %s: %d wrong id, %d false positive; found",
                         detectors[d]->name().c_str(), size.width, size.height, seed,
                         test::toString(conditions[c]).c_str(), frame_score.wrong_id,
                         frame_score.false_positive);
            for (const test::FoundMarker& m : found) std::fprintf(stderr, " %d", m.id);
            std::fprintf(stderr, "; drawn");
            for (const int id : scene.ids) std::fprintf(stderr, " %d", id);
            std::fprintf(stderr, "\n");
          }
          for (size_t m = 0; m < scene.markers.size(); ++m) {
            const int bin = sideBin(scene.markers[m]);
            ++cell.truth_by_side[bin];
            const int hit = test::scoreFrame({scene.ids[m]}, {scene.markers[m]}, found,
                                             detectors[d]->orderedCorners())
                                .found;
            cell.found_by_side[bin] += hit;
            if (hit) continue;
            if (const auto miss =
                    detectors[d]->explainMiss(scene.image, scene.markers[m], scene.ids[m])) {
              ++cell.missed;
              cell.missed_with_square += miss->square_on_it;
              cell.missed_readable += miss->readable_at_truth;
            }
          }
          cell.seconds += seconds;
          if (const auto stages = detectors[d]->lastStageTimes()) cell.stages += *stages;
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
    for (size_t d = 0; d < ours; ++d) {
      std::printf(
          "\n%s: time per stage, %dx%d (us per frame)\n%-13s %7s %7s %7s %7s %7s %7s %7s %7s "
          "%7s\n",
          detectors[d]->name().c_str(), size.width, size.height, "condition", "smooth", "thresh",
          "label", "quads", "retry", "refine", "decode", "other", "total");
      for (size_t c = 0; c < conditions.size(); ++c) {
        const Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
        const vision::StageTimes& t = cell.stages;
        const double n = cell.frames;
        const double other = t.other + t.convert;
        std::printf("%-13s %7.0f %7.0f %7.0f %7.0f %7.0f %7.0f %7.0f %7.0f %7.0f\n",
                    test::toString(conditions[c]).c_str(), t.smooth / n, t.threshold / n,
                    t.label / n, t.quads / n, t.retry / n, t.refine / n, t.decode / n, other / n,
                    t.total / n);
      }
    }
    for (size_t d = 0; d < ours; ++d) {
      std::printf(
          "\n%s: its misses, %dx%d (a square on the marker: the search found its outline; read at "
          "the true corners: its code is readable there)\n%-13s %7s %16s %22s\n",
          detectors[d]->name().c_str(), size.width, size.height, "condition", "missed",
          "square on it", "read at true corners");
      for (size_t c = 0; c < conditions.size(); ++c) {
        const Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
        std::printf("%-13s %7d %16d %22d\n", test::toString(conditions[c]).c_str(), cell.missed,
                    cell.missed_with_square, cell.missed_readable);
      }
    }
    if (by_side) {
      std::printf("\nrecall by apparent marker side, %dx%d (markers in the bin)\n%-30s %-13s",
                  size.width, size.height, "detector", "condition");
      for (int b = 0; b < kSideBinCount; ++b) {
        char label[32];
        if (b + 1 < kSideBinCount)
          std::snprintf(label, sizeof label, "%.0f-%.0f", kSideBins[b], kSideBins[b + 1]);
        else
          std::snprintf(label, sizeof label, ">=%.0f", kSideBins[b]);
        std::printf(" %13s", label);
      }
      std::printf("\n");
      for (size_t d = 0; d < detectors.size(); ++d) {
        for (size_t c = 0; c < conditions.size(); ++c) {
          const Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
          std::printf("%-30s %-13s", detectors[d]->name().c_str(),
                      test::toString(conditions[c]).c_str());
          for (int b = 0; b < kSideBinCount; ++b) {
            const int n = cell.truth_by_side[b];
            std::printf("   %5.3f (%3d)", n ? static_cast<double>(cell.found_by_side[b]) / n : 0.0,
                        n);
          }
          std::printf("\n");
        }
      }
    }
    std::printf("\nmean time per frame over the %zu conditions, %dx%d:\n", conditions.size(),
                size.width, size.height);
    if (detectors.size() == ours) {
      for (size_t d = 0; d < ours; ++d)
        std::printf("  %-30s %8.3f ms\n", detectors[d]->name().c_str(), mean_ms[d]);
      continue;
    }
    const double fastest_peer =
        *std::min_element(mean_ms.begin() + static_cast<std::ptrdiff_t>(ours), mean_ms.end());
    for (size_t d = 0; d < detectors.size(); ++d) {
      std::printf("  %-30s %8.3f ms  (%.2fx the fastest peer)\n", detectors[d]->name().c_str(),
                  mean_ms[d], mean_ms[d] / fastest_peer);
    }
    for (size_t d = 0; d < ours; ++d) {
      std::printf(
          "by condition, %s against the best peer's recall and the fastest peer's time:\n"
          "  %-13s %6s %9s %9s %9s %7s\n",
          detectors[d]->name().c_str(), "condition", "ARBCI", "best peer", "ARBCI ms", "peer ms",
          "ratio");
      for (size_t c = 0; c < conditions.size(); ++c) {
        double best_peer = 0.0, fastest_ms = 1e300;
        for (size_t p = ours; p < detectors.size(); ++p) {
          const Cell& cell = cells[{static_cast<int>(p), static_cast<int>(c)}];
          best_peer = std::max(best_peer, cell.score.recall());
          fastest_ms = std::min(fastest_ms, 1000.0 * cell.seconds / cell.frames);
        }
        const Cell& cell = cells[{static_cast<int>(d), static_cast<int>(c)}];
        const double ours_ms = 1000.0 * cell.seconds / cell.frames;
        // Three decimals: at two, a row just over the line printed "0.50x" over the target.
        std::printf("  %-13s %6.3f %9.3f %9.3f %9.3f %6.3fx %s%s\n",
                    test::toString(conditions[c]).c_str(), cell.score.recall(), best_peer, ours_ms,
                    fastest_ms, ours_ms / fastest_ms,
                    cell.score.recall() >= best_peer ? "" : "recall BELOW ",
                    ours_ms <= kTargetTimeRatio * fastest_ms ? "" : "time over the target");
      }
    }
  }
  if (detections) std::fclose(detections);
  return 0;
}
