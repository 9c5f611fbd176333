#include "arbci/vision/marker_poses.h"

#include <optional>
#include <stdexcept>

namespace arbci::vision {

MarkerPoses::MarkerPoses(const cv::Matx33d& camera_matrix, const PoseOptions& options)
    : camera_matrix_(camera_matrix), options_(options) {}

std::map<int, PoseEstimate> MarkerPoses::estimate(const std::vector<MarkerDetection>& markers,
                                                  const SizeOf& size_of) {
  std::map<int, PoseEstimate> poses;
  for (const MarkerDetection& m : markers) {
    const double side = size_of(m.id);
    if (side <= 0.0) continue;
    auto pixels = [](const std::array<cv::Point2f, 4>& corners) {
      std::vector<cv::Point2d> image;
      for (const cv::Point2f& p : corners) image.emplace_back(p.x, p.y);
      return image;
    };
    PoseOptions options = options_;
    if (const auto previous = previous_.find(m.id); previous != previous_.end())
      options.previous = previous->second;
    try {
      const auto object = markerCorners(side);
      std::optional<PoseEstimate> measured;
      if (m.measured_ideal_corners) {
        // Smoothed: the measured corners choose the planar solution, and bound the smoothing.
        measured = estimatePose(object, pixels(*m.measured_ideal_corners), camera_matrix_, options);
        options.previous = measured->pose;
        options.ambiguity_ratio = 1e9;  // always the solution nearer the measured one
      }
      PoseEstimate estimate =
          estimatePose(object, pixels(m.ideal_corners), camera_matrix_, options);
      if (measured && rotationAngleDeg(estimate.pose.rotation, measured->pose.rotation) >
                          options_.max_smoothing_deg)
        estimate = *measured;
      poses[m.id] = estimate;
      previous_[m.id] = estimate.pose;
    } catch (const std::exception&) {
      // A degenerate quad (collinear corners): no pose this frame.
    }
  }
  return poses;
}

}  // namespace arbci::vision
