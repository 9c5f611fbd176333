#include "arbci/vision/template_pattern.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

namespace arbci::vision {
namespace {

constexpr int kN = TemplatePattern::kSize;

std::vector<float> turnAnticlockwise(const std::vector<float>& pattern) {
  std::vector<float> turned(pattern.size());
  // Anticlockwise: the cell at (r, c) moves to (n - 1 - c, r).
  for (int r = 0; r < kN; ++r) {
    for (int c = 0; c < kN; ++c) turned[(kN - 1 - c) * kN + r] = pattern[r * kN + c];
  }
  return turned;
}

// Normalised cross-correlation of two equally sized patterns (0 when either is flat).
float correlation(const std::vector<float>& a, const std::vector<float>& b) {
  double mean_a = 0, mean_b = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(a.size());
  mean_b /= static_cast<double>(b.size());
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double da = a[i] - mean_a, db = b[i] - mean_b;
    ab += da * db;
    aa += da * da;
    bb += db * db;
  }
  if (aa <= 1e-9 || bb <= 1e-9) return 0.0f;
  return static_cast<float>(ab / std::sqrt(aa * bb));
}

}  // namespace

TemplatePattern TemplatePattern::fromUpright(int id, std::string name,
                                             const std::vector<float>& upright) {
  if (upright.size() != static_cast<size_t>(kN * kN)) {
    throw std::invalid_argument("a template pattern needs 16 x 16 samples");
  }
  TemplatePattern pattern;
  pattern.id = id;
  pattern.name = std::move(name);
  pattern.rotations[0] = upright;
  for (int t = 1; t < 4; ++t) pattern.rotations[t] = turnAnticlockwise(pattern.rotations[t - 1]);
  return pattern;
}

TemplatePattern TemplatePattern::load(const std::filesystem::path& path, int id) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open pattern file");
  TemplatePattern pattern;
  pattern.id = id;
  pattern.name = path.stem().string();
  for (int t = 0; t < 4; ++t) {
    std::vector<float> grey(kN * kN, 0.0f);
    for (int plane = 0; plane < 3; ++plane) {
      // Planes are stored blue, green, red; (B + 2G + R) / 4 is symmetric in the two.
      const float weight = plane == 1 ? 0.5f : 0.25f;
      for (int i = 0; i < kN * kN; ++i) {
        int value = -1;
        if (!(in >> value) || value < 0 || value > 255) {
          throw std::runtime_error(path.string() + ": expected 4 x 3 x 256 values 0..255, value " +
                                   std::to_string(t * 768 + plane * 256 + i + 1) +
                                   " is missing or bad");
        }
        grey[i] += weight * static_cast<float>(value);
      }
    }
    pattern.rotations[t] = std::move(grey);
  }
  return pattern;
}

void TemplatePattern::save(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path.string() + ": cannot write pattern file");
  for (int t = 0; t < 4; ++t) {
    for (int plane = 0; plane < 3; ++plane) {
      for (int r = 0; r < kN; ++r) {
        for (int c = 0; c < kN; ++c) {
          out << (c ? " " : "") << std::lround(rotations[t][r * kN + c]);
        }
        out << "\n";
      }
    }
    out << "\n";
  }
  if (!out) throw std::runtime_error(path.string() + ": write failed");
}

float TemplatePattern::rotationalSymmetry() const {
  float most = -1.0f;
  for (int t = 1; t < 4; ++t) most = std::max(most, correlation(rotations[0], rotations[t]));
  return most;
}

std::optional<TemplateMatch> matchTemplate(const std::vector<float>& sampled,
                                           const std::vector<TemplatePattern>& patterns,
                                           const TemplateMatchLimits& limits) {
  TemplateMatch best;
  float runner_up = -1.0f;  // best score of any other pattern or other orientation
  best.confidence = -1.0f;
  for (const TemplatePattern& pattern : patterns) {
    for (int t = 0; t < 4; ++t) {
      const float score = correlation(sampled, pattern.rotations[t]);
      if (score > best.confidence) {
        runner_up = std::max(runner_up, best.confidence);
        best = {pattern.id, t, score};
      } else {
        runner_up = std::max(runner_up, score);
      }
    }
  }
  if (best.confidence < limits.min_confidence) return std::nullopt;
  if (best.confidence - runner_up < limits.min_margin) return std::nullopt;
  return best;
}

}  // namespace arbci::vision
