// Renders markers at known 3D poses through a pinhole camera (optionally adding lens distortion),
// for the geometry tests: the exact ground truth of pose, calibration and robot-frame checks.
#pragma once

#include <opencv2/core/mat.hpp>

#include "arbci/vision/camera_model.h"
#include "arbci/vision/pose.h"
#include "synthetic_markers.h"

namespace arbci::test {

// Draws `family`'s marker `id` with its black square of side `side_m` at `T_cam_marker`
// (ARToolKitPlus marker frame: x right, y up, z out of the print) into `frame` (ideal pinhole
// camera `camera_matrix`). Returns the true ideal corners TL TR BR BL.
Corners drawPosedMarker(cv::Mat& frame, const cv::Matx33d& camera_matrix,
                        const vision::Pose& T_cam_marker, double side_m, MarkerFamily family,
                        int id);

// What the real (distorting) camera sees of an ideal image (same camera matrix): maps computed
// once per camera, applied to any number of frames.
class DistortingCamera {
 public:
  explicit DistortingCamera(const vision::CameraModel& camera);
  cv::Mat operator()(const cv::Mat& ideal) const;

 private:
  cv::Mat map_x_, map_y_;
};

// A rotation that tilts a marker facing the camera by `tilt_deg` about the axis at `azimuth_deg`
// in the image plane, after turning it by `spin_deg` about its normal.
cv::Matx33d markerRotation(double tilt_deg, double azimuth_deg, double spin_deg);

}  // namespace arbci::test
