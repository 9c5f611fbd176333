#include "support/occluded_markers.h"

#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

#include "arbci/vision/pose.h"
#include "support/posed_markers.h"

namespace arbci::test {

OccludedFrame occludedMarkerFrame(MarkerFamily family, int id, Occluder occluder,
                                  double min_fraction, double max_fraction, unsigned seed) {
  std::mt19937 random(seed);
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<>(a, b)(random); };
  const cv::Size size(640, 480);
  const cv::Matx33d k(560, 0, 319.5, 0, 560, 239.5, 0, 0, 1);
  constexpr double kSideM = 0.06;
  const double side_px = uniform(50.0, 130.0);
  const double distance = 560.0 * kSideM / side_px;
  // Inside the frame with a margin of a side and a half around the centre.
  const double margin = 1.5 * side_px;
  const double u = uniform(margin, size.width - margin), v = uniform(margin, size.height - margin);
  vision::Pose pose;
  pose.rotation = markerRotation(uniform(0.0, 40.0), uniform(0.0, 360.0), uniform(0.0, 360.0));
  pose.translation = cv::Vec3d((u - 319.5) / 560.0, (v - 239.5) / 560.0, 1.0) * distance;
  const int corner = static_cast<int>(uniform(0.0, 4.0)) % 4;
  const double fraction = uniform(min_fraction, max_fraction);

  OccludedFrame out;
  cv::Mat frame(size, CV_8UC1, cv::Scalar(150));
  out.truth = drawPosedMarker(frame, k, pose, kSideM, family, id);
  double sides = 0.0;
  for (int c = 0; c < 4; ++c) sides += cv::norm(out.truth[(c + 1) % 4] - out.truth[c]);
  const double radius = fraction * sides / 4.0;
  const cv::Point2f at = out.truth[corner];
  // Sub-pixel disc (4 fractional bits), anti-aliased: a finger's rounded edge.
  cv::circle(
      frame,
      cv::Point(static_cast<int>(std::lround(at.x * 16)), static_cast<int>(std::lround(at.y * 16))),
      static_cast<int>(std::lround(radius * 16)), cv::Scalar(occluder == Occluder::Dark ? 30 : 225),
      cv::FILLED, cv::LINE_AA, 4);
  cv::GaussianBlur(frame, frame, cv::Size(0, 0), 0.7);
  cv::Mat noise(size, CV_16S);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  cv::Mat noisy;
  frame.convertTo(noisy, CV_16S);
  cv::Mat(noisy + noise).convertTo(out.image, CV_8U);
  return out;
}

}  // namespace arbci::test
