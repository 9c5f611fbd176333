#include "arbci/vision/marker_poses.h"

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
    std::vector<cv::Point2d> image;
    for (const cv::Point2f& p : m.ideal_corners) image.emplace_back(p.x, p.y);
    PoseOptions options = options_;
    if (const auto previous = previous_.find(m.id); previous != previous_.end())
      options.previous = previous->second;
    try {
      const auto object = markerCorners(side);
      const PoseEstimate estimate = estimatePose(object, image, camera_matrix_, options);
      poses[m.id] = estimate;
      previous_[m.id] = estimate.pose;
    } catch (const std::exception&) {
      // A degenerate quad (collinear corners): no pose this frame.
    }
  }
  return poses;
}

}  // namespace arbci::vision
