// How the tracker binarises frames: constant; automatic from the last frame's markers (median of
// the marker's pixels, as the original system; midrange of the patterns, as ARToolKitPlus), with
// a random threshold each frame while nothing is found; vignetting compensation; and local
// adaptive thresholding for lighting that defeats any single threshold.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace arbci::vision {

enum class ThresholdMode { Constant, AutoMedian, AutoMidrange, Adaptive };

std::string toString(ThresholdMode mode);
// "constant", "auto-median", "auto-midrange", "adaptive"; throws std::invalid_argument.
ThresholdMode thresholdModeFromString(const std::string& text);

// ARToolKitPlus's radial fall-off compensation: these offsets are added to the threshold at the
// image corners, at mid-left/right and at mid-top/bottom (0 at the centre, piecewise linear in
// between); negative values lower the threshold where the lens darkens the image.
struct Vignetting {
  int corners = 0;
  int left_right = 0;
  int top_bottom = 0;
};

struct ThresholdSettings {
  ThresholdMode mode = ThresholdMode::Adaptive;
  int value = 100;  // the constant threshold, or the starting one of the automatic modes
  std::optional<Vignetting> vignetting;  // global modes only
  // Automatic modes: extra attempts within a frame with a random threshold in [10, 239] when no
  // square is found (ARToolKitPlus does 2); the drawn threshold persists to the next frame.
  int retries_per_frame = 2;
  std::uint32_t random_seed = 12345;
  // Adaptive: the least local contrast (grey levels) that counts as an edge; 0 = from the
  // frame's estimated noise.
  int min_contrast = 0;
};

}  // namespace arbci::vision
