// The poses of a camera's detected markers, frame after frame: each from its ideal (undistorted)
// corners and the size of its black square, seeded with the marker's previous pose so a marker
// seen nearly face-on does not flip between the two planar solutions. Where the tracker smoothed
// the corners, the corners as measured choose between the two solutions, and a smoothed pose
// more than PoseOptions::max_smoothing_deg from the measured one gives way to it: smoothing
// takes out jitter, never adds a flip. The session's tracking and
// `arbci detect --camera` both estimate poses through it.
#pragma once

#include <functional>
#include <map>
#include <vector>

#include "arbci/vision/marker.h"
#include "arbci/vision/pose.h"

namespace arbci::vision {

class MarkerPoses {
 public:
  MarkerPoses(const cv::Matx33d& camera_matrix, const PoseOptions& options = {});

  // Side in metres of marker `id`'s black square; 0 or less: not a marker to estimate.
  using SizeOf = std::function<double(int id)>;
  // Poses of this frame's markers, by id. A degenerate quad gets none (and keeps its previous).
  std::map<int, PoseEstimate> estimate(const std::vector<MarkerDetection>& markers,
                                       const SizeOf& size_of);
  void forget(int id) { previous_.erase(id); }
  void clear() { previous_.clear(); }

 private:
  cv::Matx33d camera_matrix_;
  PoseOptions options_;
  std::map<int, Pose> previous_;
};

}  // namespace arbci::vision
