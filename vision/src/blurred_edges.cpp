#include "blurred_edges.h"

#include <algorithm>
#include <cmath>

#include "image_sampling.h"
#include "side_geometry.h"

namespace arbci::vision {

using namespace side_geometry;

namespace {

// Motion blur smears the border across the sides it crosses: such a side's edge is a ramp as wide
// as the smear (9-15 px), wider than refineSide()'s reach, and the binarised outline ends partway
// down it, outside the printed edge (the bench's smeared markers came out 2-7 px too large along
// the motion). Where the box kernel passes the edge it covers light surround and black border
// only, so the ramp falls linearly from the surround's level and reaches the middle of the
// surround and the black at the printed edge: found where the profile crosses 15 % and 35 % of
// the way down, extended to 50 %. A sharp edge gives the mid-level crossing, as refineSide().
constexpr int kRampOutside = 12, kRampInside = 8;  // profile reach across the side, px
constexpr float kRampStep = 1.0f;                  // px between profile samples
constexpr int kRampSamples = static_cast<int>((kRampOutside + kRampInside) / kRampStep) + 1;
constexpr int kRampProfiles = 8;           // per side, spread over its middle 70 %
constexpr float kMinRampContrast = 16.0f;  // grey levels between surround and black
constexpr float kLeastSmearRamp = 1.3f;    // px from 15 % to 35 % of the way down, on some side
using RampProfiles = float[kRampProfiles][kRampSamples];  // outside to inside

float rampProfileAt(int s) {
  return 0.15f + 0.7f * (static_cast<float>(s) + 0.5f) / static_cast<float>(kRampProfiles);
}

constexpr float kNearLevel = 0.15f, kFarLevel = 0.35f;  // of the way from surround to black

// Where a profile (samples from outside in) first falls 15 % and 35 % of the way from its
// surround (the lightest sample at least 2 px outside the side) to `black`, as sample indices;
// nullopt when it shows no such ramp.
struct RampCrossings {
  float near_at, far_at;
  float edge() const {  // the printed edge, 50 % of the way down a linear ramp
    return near_at + (0.5f - kNearLevel) / (kFarLevel - kNearLevel) * (far_at - near_at);
  }
};
std::optional<RampCrossings> rampCrossings(const float* profile, float black) {
  constexpr int kLast = static_cast<int>((kRampOutside - 2) / kRampStep);
  int light = 0;
  for (int i = 1; i <= kLast; ++i)
    if (profile[i] >= profile[light]) light = i;
  const float surround = profile[light], contrast = surround - black;
  if (contrast < kMinRampContrast) return std::nullopt;
  const float near_level = surround - kNearLevel * contrast;
  const float far_level = surround - kFarLevel * contrast;
  float near_at = -1.0f;
  for (int i = light; i + 1 < kRampSamples; ++i) {
    const float p = profile[i], q = profile[i + 1];
    if (near_at < 0.0f && p >= near_level && q < near_level)
      near_at = static_cast<float>(i) + (p - near_level) / (p - q);
    if (near_at >= 0.0f && p >= far_level && q < far_level)
      return RampCrossings{near_at, static_cast<float>(i) + (p - far_level) / (p - q)};
  }
  return std::nullopt;
}

// A line through the side's ramp edges; profiles that met a neighbouring shape instead are
// dropped (over 1.5 px off a first fit) and the line fitted again.
std::optional<Line> lineOnRamps(const LensMap& lens, cv::Point2f a, cv::Point2f b,
                                const RampProfiles& profiles, float black) {
  const cv::Point2f d = b - a;
  const cv::Point2f along = d / length(d), ideal_outward(along.y, -along.x);
  cv::Point2f points[kRampProfiles];
  float weights[kRampProfiles];
  int count = 0;
  for (int s = 0; s < kRampProfiles; ++s) {
    const auto ramp = rampCrossings(profiles[s], black);
    if (!ramp) continue;
    const cv::Point2f ideal_base = a + rampProfileAt(s) * d;
    const float outward_px = static_cast<float>(kRampOutside) - ramp->edge() * kRampStep;
    points[count] = lens.toIdeal(lens.toImage(ideal_base) +
                                 outward_px * outwardInImage(lens, ideal_base, ideal_outward));
    weights[count++] = 1.0f;
  }
  if (count < 4) return std::nullopt;
  const auto first = fitLine(points, weights, count);
  if (!first) return std::nullopt;
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const cv::Point2f r = points[i] - first->point;
    if (std::abs(r.x * first->direction.y - r.y * first->direction.x) <= 1.5f)
      points[kept++] = points[i];
  }
  if (kept < 4) return std::nullopt;
  return fitLine(points, weights, kept);
}

// A quad's ramp profiles (RampProfiles per side), sampled as they are needed.
class SideProfiles {
 public:
  SideProfiles(const Quad& quad, const cv::Mat& image, const QuadFitParams& params)
      : lens_{params.lens},
        ideal_(quad.ideal_corners),
        sample_(image, sidesRegion(lens_, ideal_, static_cast<float>(kRampOutside + 2))) {}

  const LensMap& lens() const { return lens_; }
  const std::array<cv::Point2f, 4>& ideal() const { return ideal_; }
  const RampProfiles& side(int k) const { return profiles_[k]; }

  // Samples profile s of side k; returns its darkest sample inside the quad.
  float sample(int k, int s) {
    constexpr int kFirstInside = static_cast<int>(kRampOutside / kRampStep) + 1;
    const cv::Point2f a = ideal_[k], d = ideal_[(k + 1) % 4] - a;
    const cv::Point2f along = d / length(d), ideal_outward(along.y, -along.x);
    const cv::Point2f ideal_base = a + rampProfileAt(s) * d;
    const cv::Point2f inward = -outwardInImage(lens_, ideal_base, ideal_outward);
    const cv::Point2f from = lens_.toImage(ideal_base) - static_cast<float>(kRampOutside) * inward;
    float* profile = profiles_[k][s];
    sample_.line(from.x, from.y, kRampStep * inward.x, kRampStep * inward.y, kRampSamples, profile);
    return *std::min_element(profile + kFirstInside, profile + kRampSamples);
  }

  // From the two middle profiles of each side: whether some side's edge is a ramp (a sharp edge
  // falls from 15 % to 35 % within 0.5 px, Gaussian blur of sigma 1.5 px within 1; a 9 px smear
  // across it in 1.8 px, at 45 degrees in 1.3). `black`: the darkest sample inside them.
  bool smeared(float& black) {
    constexpr int kMiddle = kRampProfiles / 2 - 1;
    black = 255.0f;
    for (int k = 0; k < 4; ++k)
      black = std::min({black, sample(k, kMiddle), sample(k, kMiddle + 1)});
    float widest = 0.0f;
    for (int k = 0; k < 4; ++k) {
      float mean[kRampSamples];  // of the two: half the noise
      for (int i = 0; i < kRampSamples; ++i)
        mean[i] = 0.5f * (profiles_[k][kMiddle][i] + profiles_[k][kMiddle + 1][i]);
      if (const auto ramp = rampCrossings(mean, black))
        widest = std::max(widest, (ramp->far_at - ramp->near_at) * kRampStep);
    }
    return widest >= kLeastSmearRamp;
  }

 private:
  LensMap lens_;
  std::array<cv::Point2f, 4> ideal_;
  BilinearSampler sample_;
  RampProfiles profiles_[4];
};

bool sidesLongEnough(const Quad& quad, const QuadFitParams& params) {
  for (int k = 0; k < 4; ++k) {
    if (length(quad.ideal_corners[(k + 1) % 4] - quad.ideal_corners[k]) < params.min_side)
      return false;
  }
  return true;
}

}  // namespace

bool looksSmeared(const Quad& quad, const cv::Mat& image, const QuadFitParams& params) {
  if (!sidesLongEnough(quad, params)) return false;
  SideProfiles profiles(quad, image, params);
  float black = 0.0f;
  return profiles.smeared(black);
}

std::optional<Quad> placeOnBlurredEdges(const Quad& quad, const cv::Mat& image,
                                        const QuadFitParams& params) {
  if (!sidesLongEnough(quad, params)) return std::nullopt;
  SideProfiles profiles(quad, image, params);
  // Unless some side's edge is a ramp, the quad stays where it is.
  float black = 0.0f;
  if (!profiles.smeared(black)) return std::nullopt;
  // Then the rest: the black level is the darkest sample inside the quad.
  constexpr int kMiddle = kRampProfiles / 2 - 1;
  for (int k = 0; k < 4; ++k) {
    for (int s = 0; s < kRampProfiles; ++s) {
      if (s != kMiddle && s != kMiddle + 1) black = std::min(black, profiles.sample(k, s));
    }
  }
  const std::array<cv::Point2f, 4>& ideal = profiles.ideal();
  const LensMap& lens = profiles.lens();
  std::array<Line, 4> lines;
  for (int k = 0; k < 4; ++k) {
    const auto line = lineOnRamps(lens, ideal[k], ideal[(k + 1) % 4], profiles.side(k), black);
    if (!line) return std::nullopt;
    lines[k] = *line;
  }
  Quad placed;
  if (!intersectLines(lines, placed.corners) || !finishQuad(params, lens, placed))
    return std::nullopt;
  return placed;
}

}  // namespace arbci::vision
