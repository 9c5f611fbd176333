// The square-marker tracker for one camera: pixel format conversion, thresholding, connected
// components, contour tracing, quad fitting with sub-pixel edges, pattern normalisation and ID
// decoding (BCH and simple IDs as ARToolKitPlus, trained templates), or OpenCV's ArUco/AprilTag
// dictionaries. It keeps the automatic threshold between frames; one detector per camera.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"
#include "arbci/vision/pixel_format.h"
#include "arbci/vision/search_passes.h"
#include "arbci/vision/template_pattern.h"
#include "arbci/vision/threshold.h"
#include "arbci/vision/undistortion.h"

namespace arbci::vision {

enum class Smoothing { Auto, Always, Never };

// kind, border, search_decimate, apriltag_refine_edges and passes are settings: their defaults
// and ranges are vision::detectorSchema()'s (vision/settings.h); the rest is set by the caller.
struct DetectorConfig {
  DetectorConfig();
  MarkerKind kind;
  // Border width as a fraction of the marker side: 0.125 (thin) or 0.25 (standard), or any other
  // value in (0, 0.4] for square kinds.
  double border;
  ThresholdSettings threshold;
  // 3x3 binomial blur before binarising: Auto smooths frames whose estimated noise reaches
  // passes.smooth_above_noise (sensor noise) or that show JPEG's 8 px block edges (an MJPEG
  // camera), and leaves other frames sharp. A frame searched at half resolution (search_decimate
  // 2) is not smoothed.
  Smoothing smoothing = Smoothing::Auto;
  float min_side_px = 8;  // smaller squares are ignored
  // The ids the caller expects in view (a session: its reference and objects); empty: unknown.
  // The edge-segment pass (passes.edge_segments, the costliest) then runs only on frames where
  // the outline search missed one of them, e.g. an object whose corner a hand covers.
  std::set<int> expected_ids;
  // Square kinds: 1 looks for candidates at full resolution; 2 thresholds, labels and fits quads
  // on the frame averaged over 2x2 pixels (a quarter of the pixels), then moves every side onto
  // the full-resolution edge, as AprilTag's quad_decimate. About twice as fast; markers need about
  // 24 px per side (a border of 3 px) to be found.
  int search_decimate;
  // BCH only: when ARToolKitPlus's hard decoding (at most 2 corrected bits) fails, try Chase
  // decoding on the least reliable cells (recovers blurred markers; see code_decoder.h).
  bool soft_decoding = true;
  // Square kinds: the search's passes after its first (search_passes.h).
  SearchPasses passes;
  std::vector<TemplatePattern> templates;  // MarkerKind::Template
  TemplateMatchLimits template_limits;
  // The camera's lens (its calibration and an undistortion mode): sides are fitted straight in
  // undistorted coordinates and ideal corners are reported. Frames must match its image size.
  std::shared_ptr<const Undistorter> lens;
  // MarkerKind::Aruco: an OpenCV predefined dictionary name (empty: DICT_6X6_250).
  // MarkerKind::AprilTag: a libapriltag family (tag36h11, tagStandard41h12, ...; OpenCV's
  // DICT_APRILTAG_* names the same families; empty: tag36h11), found by libapriltag itself.
  std::string dictionary;
  // MarkerKind::AprilTag: libapriltag's edge refinement (its default, on), which moves each side
  // onto the strongest gradient; off gives the corners of the library's regression references.
  bool apriltag_refine_edges;
};

using SquareCorners = std::array<cv::Point2f, 4>;

class MarkerDetector {
 public:
  // Throws std::invalid_argument naming the field when the configuration is unusable.
  explicit MarkerDetector(DetectorConfig config);
  ~MarkerDetector();
  MarkerDetector(MarkerDetector&&) noexcept;
  MarkerDetector& operator=(MarkerDetector&&) noexcept;

  // A gray, BGR or BGRA 8-bit image; an empty image gives no markers.
  DetectionResult detect(const cv::Mat& image);
  // A frame in any supported pixel format.
  DetectionResult detect(const ImageView& image);

  // Reads a marker of the configured ARToolKitPlus-style kind (BCH, simple, template) at
  // `corners`, the outline of its black square in image pixels, as given: no search and no
  // refinement (either turn; counter-clockwise corners are reordered). Tells a marker the search
  // missed from one that cannot be read (marker_bench's miss analysis); the last frame's results
  // are left as they were. Throws std::invalid_argument for the ArUco and AprilTag kinds.
  std::optional<MarkerDetection> readAt(const cv::Mat& image, const SquareCorners& corners) const;

  const DetectorConfig& config() const;
  void setThreshold(const ThresholdSettings& settings);
  // The global threshold the next frame starts from (automatic and constant modes).
  int currentThreshold() const;
  // The last frame's square outlines, decoded or not (clockwise on screen), in image and in ideal
  // coordinates (by index); squares inside a decoded marker (its code cells) are left out.
  const std::vector<SquareCorners>& lastSquares() const;
  const std::vector<SquareCorners>& lastIdealSquares() const;
  // The last frame's binary image: 255 where a pixel counted as dark.
  cv::Mat lastBinaryImage() const;
  // The luminance image of the last frame (shares memory with the detector; copy to keep).
  const cv::Mat& lastGrayImage() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The OpenCV predefined dictionary names accepted for the ArUco kind.
std::vector<std::string> dictionaryNames();

}  // namespace arbci::vision

namespace arbci::vision {

// A template pattern from an image of one marker seen face-on and upright: the largest dark
// square's code area (inside `border`) sampled on a 16x16 grid; nullopt when no square is found.
std::optional<TemplatePattern> trainTemplate(const cv::Mat& image, int id, double border);

}  // namespace arbci::vision
