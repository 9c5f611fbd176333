// Synthetic camera frames of square markers with exact ground truth, for tests and benchmarks.
// A layout (marker and decoy poses, background, lighting) is drawn once and rendered with each
// marker family, so every detector sees the same scene with its own markers. Every family is drawn
// as an 8-cell black square (1-cell black border, 6 x 6 code) inside a white quiet zone, 1 cell
// wide unless the layout asks for more; a marker's size is the side of its black square.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace arbci::test {

enum class MarkerFamily { ArbciBch, Aruco6x6, AprilTag36h11 };
// MotionBlur: a linear kernel 5-15 px long at a random angle (a head-mounted camera turning
// during the exposure); MotionBlurJpeg: the same, then JPEG at quality 50 (a compressing camera);
// FastMotionJpeg: a 9-15 px kernel (a faster head turn), then JPEG at quality 50. Cluttered: the
// scene drawn over a photograph (SceneLayout::backdrop) instead of the flat synthetic table, so
// that natural texture (grass, gravel, faces, print) surrounds the markers.
enum class Condition {
  Clean,
  Blur,
  Noise,
  UnevenLight,
  Combined,
  MotionBlur,
  MotionBlurJpeg,
  FastMotionJpeg,
  Cluttered
};

std::string toString(MarkerFamily family);
std::string toString(Condition condition);

using Corners = std::array<cv::Point2f, 4>;  // TL, TR, BR, BL of the black square, OpenCV pixels

struct LayoutOptions {
  cv::Size size{640, 480};
  int markers = 3;
  int decoys = 2;
  float min_side_px = 20.0f;  // face-on size of the smallest marker
  float max_side_px = 110.0f;
  float max_tilt_deg = 60.0f;
  // What the tilt is measured from. The optical axis: a marker near the frame's edge is then seen
  // up to the tilt plus the ray's own angle (about 29 degrees at 640x480's side edges) off face-on,
  // nearly edge-on at the largest tilts. The line of sight: no marker is seen more obliquely than
  // max_tilt_deg.
  enum class TiltFrom { OpticalAxis, LineOfSight };
  TiltFrom tilt_from = TiltFrom::OpticalAxis;
  float quiet_cells = 1.0f;  // white margin around each marker, in code cells (whole cells)
};

struct SceneLayout {
  cv::Size size;
  std::vector<Corners> markers;  // poses of the markers (black square corners)
  std::vector<Corners> decoys;
  std::vector<int> decoy_styles;
  int quiet_cells = 1;     // printed white margin around each marker, cells
  std::uint32_t seed = 0;  // background and lighting
  // Condition::Cluttered's background: an 8-bit grey image of `size` (backdropFromPhotos()).
  cv::Mat backdrop;
};

struct RenderedScene {
  cv::Mat image;                 // 8-bit grey
  std::vector<int> ids;          // per layout marker
  std::vector<Corners> markers;  // ground truth, same order
};

// Random poses (tilt up to max_tilt_deg, any in-plane rotation), not overlapping each other.
SceneLayout makeLayout(const LayoutOptions& options, std::uint32_t seed);

// Draws the layout with `family`'s markers (ids drawn from the seed) under `condition`.
RenderedScene renderScene(const SceneLayout& layout, MarkerFamily family, Condition condition);

// Smears `frame` along a line `length` px long at `angle` radians (a box kernel on that line, drawn
// at 4x and reduced): a camera moving during its exposure.
void motionBlur(cv::Mat& frame, float length, float angle);

// A background for Condition::Cluttered: one of `photos` (any 8-bit images, chosen by `seed`),
// converted to grey, scaled by 1-1.5 times what covers `size` and cropped at a random place.
// Throws std::invalid_argument when `photos` is empty.
cv::Mat backdropFromPhotos(const std::vector<cv::Mat>& photos, cv::Size size, std::uint32_t seed);

// A frame of `size` with background and decoys only (no markers), under `condition`.
cv::Mat renderMarkerFree(const SceneLayout& layout, Condition condition);

// The printed marker image of `family` and `id`, (8 + 2 quiet_cells)^2 cells of `cell_px` pixels
// each (quiet zone included).
cv::Mat markerImage(MarkerFamily family, int id, int cell_px, int quiet_cells = 1);

// Ids a family offers for the benchmark: BCH ids whose rotations stay at least 5 bits from any
// other codeword (the ARToolKitPlus notes list the hazardous ones), ArUco 6x6_250's 250 and
// AprilTag 36h11's 587.
const std::vector<int>& usableIds(MarkerFamily family);

// Warps `patch` (with `alpha`, both of the same size) into `frame` so that the patch's corners
// (0,0), (w,0), (w,h), (0,h) -- in pixel-area coordinates -- land on `quad` (OpenCV pixel
// coordinates), anti-aliased by 4x supersampling.
void drawWarped(cv::Mat& frame, const cv::Mat& patch, const Corners& quad);

}  // namespace arbci::test
