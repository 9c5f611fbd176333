// Multi-marker sets: several markers at known places on a board or object give one pose from all
// their visible corners together (ARToolKit's multi-marker configurations; the .cfg format it
// defines is read).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <vector>

#include "arbci/vision/marker.h"
#include "arbci/vision/pose.h"

namespace arbci::vision {

struct MarkerPlacement {
  int id = 0;
  double size_m = 0.0;
  Pose T_set_marker;  // the marker's frame in the set's frame
};

class MarkerSet {
 public:
  MarkerSet() = default;
  explicit MarkerSet(std::vector<MarkerPlacement> markers);
  // ARToolKit's multi-marker .cfg (count; then per marker: id, width, centre x y, 3x4 transform),
  // lengths in `unit_m` metres (ARToolKit files are in millimetres). Throws CalibrationFileError
  // naming the file and the marker entry.
  static MarkerSet loadArToolKitConfig(const std::filesystem::path& path, double unit_m = 0.001);

  const std::vector<MarkerPlacement>& markers() const { return markers_; }
  // The corners (TL TR BR BL) of marker `id` in the set's frame; nullopt for ids not in the set.
  std::optional<std::array<cv::Point3d, 4>> cornersOf(int id) const;
  bool planar() const;  // all markers on the set's z = 0 plane

 private:
  std::vector<MarkerPlacement> markers_;
};

struct SetPose {
  PoseEstimate estimate;      // T_cam_set
  std::vector<int> used_ids;  // markers whose corners went into it
};

// The set's pose from the markers of `detections` that belong to it (an id detected twice in the
// frame is left out, as ARToolKit does), using their ideal corners. nullopt when none is seen.
std::optional<SetPose> estimateSetPose(const MarkerSet& set,
                                       const std::vector<MarkerDetection>& detections,
                                       const cv::Matx33d& camera_matrix,
                                       const PoseOptions& options = {});

}  // namespace arbci::vision
