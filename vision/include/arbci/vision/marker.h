// What the tracker reports: markers with ID, corners, orientation and confidence, per frame.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <opencv2/core/types.hpp>

namespace arbci::vision {

// A marker family by its name in markerFamilies() ("bch", "apriltag"), as detections and settings
// carry it. What the family is and how its markers are read is its registry entry
// (marker_family.h): nothing dispatches on the name. The constants name the families code asks
// for by name (the reference marker is BCH); a new family needs none.
struct MarkerKind {
  std::string_view name;
  friend bool operator==(MarkerKind a, MarkerKind b) { return a.name == b.name; }
  static const MarkerKind Bch, Simple, Template, Aruco, AprilTag;
};
inline const MarkerKind MarkerKind::Bch{"bch"};
inline const MarkerKind MarkerKind::Simple{"simple"};
inline const MarkerKind MarkerKind::Template{"template"};
inline const MarkerKind MarkerKind::Aruco{"aruco"};
inline const MarkerKind MarkerKind::AprilTag{"apriltag"};

std::string toString(MarkerKind kind);
// A family registered in markerFamilies(); throws std::invalid_argument naming those there are.
MarkerKind markerKindFromString(const std::string& text);

struct MarkerDetection {
  int id = -1;
  MarkerKind kind = MarkerKind::Bch;
  // Corners of the printed marker: top-left, top-right, bottom-right, bottom-left, in image
  // pixels with OpenCV's convention (pixel centres at integer coordinates).
  std::array<cv::Point2f, 4> corners;
  // The same corners undistorted (pixels of the ideal camera) when the detector has a camera
  // model; equal to `corners` otherwise. Poses are computed from these.
  std::array<cv::Point2f, 4> ideal_corners;
  // Set by a tracker that smooths corners: `ideal_corners` as this frame measured them, before
  // the smoothing (poses are kept near what was measured; see MarkerPoses).
  std::optional<std::array<cv::Point2f, 4>> measured_ideal_corners;
  // ARToolKitPlus's `dir`: clockwise quarter turns from the sampled grid to the printed one.
  int orientation = 0;
  // 1.0 for a clean decode; lower for corrected bits (ARToolKitPlus's scale) or weaker matches.
  float confidence = 0.0f;
  int corrected_bits = 0;
  // The identity was carried over from earlier frames because this frame's decode failed.
  bool from_history = false;
};

// Microseconds spent in each stage of one frame: quads is the quad search on the image searched,
// retry the re-binarised near misses and fragments, edges the quads assembled from edge segments,
// refine the decimated search's quads moved onto the frame's edges, other the work between the
// timed stages. The parts add up to total.
struct StageTimes {
  double convert = 0, smooth = 0, threshold = 0, label = 0, quads = 0, retry = 0, edges = 0,
         refine = 0, decode = 0, other = 0, total = 0;
  StageTimes& operator+=(const StageTimes& more);
};

// Every part of StageTimes with its name, in pipeline order (total is not a part).
inline constexpr std::array<std::pair<const char*, double StageTimes::*>, 10> kStageParts{{
    {"convert", &StageTimes::convert},
    {"smooth", &StageTimes::smooth},
    {"threshold", &StageTimes::threshold},
    {"label", &StageTimes::label},
    {"quads", &StageTimes::quads},
    {"retry", &StageTimes::retry},
    {"edges", &StageTimes::edges},
    {"refine", &StageTimes::refine},
    {"decode", &StageTimes::decode},
    {"other", &StageTimes::other},
}};

// Of several timings of the same frame, the one whose total is the median: a whole run, so its
// parts still add up to its total (the medians of each part would not). Empty: all zero.
StageTimes medianRun(std::vector<StageTimes> runs);

struct DetectionResult {
  std::vector<MarkerDetection> markers;
  int threshold = 0;           // the global threshold used (adaptive: the median local threshold)
  std::string threshold_mode;  // how it was chosen this frame
  int candidates = 0;          // square candidates examined
  int threshold_attempts = 1;  // > 1 when a random re-acquisition threshold was tried
  StageTimes timing;
};

}  // namespace arbci::vision
