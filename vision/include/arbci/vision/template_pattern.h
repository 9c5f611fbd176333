// Template markers as ARToolKit's .patt: the code area of a square marker sampled on a 16x16 grid
// in four orientations, recognised by normalised cross-correlation. Patterns are trained from an
// image of the marker seen face-on.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace arbci::vision {

struct TemplatePattern {
  static constexpr int kSize = 16;
  int id = 0;
  std::string name;
  // Grey levels (0..255) of the code area, row-major; rotations[t] is the printed pattern turned
  // t quarter turns anticlockwise, so matching rotation t means orientation t.
  std::array<std::vector<float>, 4> rotations;

  // From the printed (upright) pattern's grey levels, kSize x kSize.
  static TemplatePattern fromUpright(int id, std::string name, const std::vector<float>& upright);
  // Reads an ARToolKit .patt file (4 orientations x 3 colour planes x 16 rows of 16 values;
  // colour is averaged to grey). Throws std::runtime_error naming the file and the problem.
  static TemplatePattern load(const std::filesystem::path& path, int id);
  void save(const std::filesystem::path& path) const;
  // The largest rotational similarity: near 1 means the orientation cannot be told apart.
  float rotationalSymmetry() const;
};

struct TemplateMatch {
  int id = -1;
  int orientation = 0;
  float confidence = 0.0f;  // normalised cross-correlation of the best match
};

struct TemplateMatchLimits {
  float min_confidence = 0.6f;
  float min_margin = 0.08f;  // best minus the next other pattern (or other orientation)
};

// The best pattern and orientation for a sampled code area (kSize x kSize); nullopt when the best
// is too weak or not clearly better than another pattern or orientation.
std::optional<TemplateMatch> matchTemplate(const std::vector<float>& sampled,
                                           const std::vector<TemplatePattern>& patterns,
                                           const TemplateMatchLimits& limits = {});

}  // namespace arbci::vision
