// Rigid poses and their estimation from planar targets: Robust Planar Pose (Schweighofer & Pinz
// 2006), OpenCV's IPPE, or OpenCV's iterative solver, optionally refined on the reprojection error
// (the seed's equation 6.2), with the error reported. Marker frames follow ARToolKitPlus: corners
// top-left (-w/2, +w/2, 0), top-right (+w/2, +w/2, 0), bottom-right, bottom-left; x right, y up
// on the print, z out of it. Camera frames follow OpenCV: x right, y down, z forward.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>

#include <opencv2/core/matx.hpp>
#include <opencv2/core/types.hpp>

namespace arbci::vision {

// x_to = R x_from + t; named T_to_from in code (T_cam_marker maps marker to camera coordinates).
struct Pose {
  cv::Matx33d rotation = cv::Matx33d::eye();
  cv::Vec3d translation{0.0, 0.0, 0.0};  // metres

  cv::Vec3d apply(const cv::Vec3d& point) const { return rotation * point + translation; }
  Pose inverse() const;
  Pose operator*(const Pose& other) const;  // this after other
  static Pose fromRotationVector(const cv::Vec3d& rvec, const cv::Vec3d& t);
  cv::Vec3d rotationVector() const;
};

// The angle in degrees of the rotation between two poses' orientations.
double rotationAngleDeg(const cv::Matx33d& a, const cv::Matx33d& b);
// The rotation of a unit quaternion (w, x, y, z), as the robot's status reports an object's.
cv::Matx33d rotationFromQuaternion(const std::array<double, 4>& wxyz);

enum class PoseMethod { Rpp, Ippe, Iterative };
std::string toString(PoseMethod method);
PoseMethod poseMethodFromString(const std::string& text);  // rpp, ippe, iterative

struct PoseOptions {
  PoseMethod method = PoseMethod::Rpp;
  bool refine = true;  // Levenberg-Marquardt on the reprojection error
  // Across frames: when the two planar solutions are this close in error, keep the one nearer
  // the previous pose, so a marker seen nearly face-on does not flip.
  std::optional<Pose> previous;
  double ambiguity_ratio = 2.0;
  // Smoothed corners (MarkerPoses): a pose from them that turns further than this from the pose
  // of the corners as measured is not jitter taken out but lag, or the other planar solution
  // (a smoothed quad is no exact view of a square): the measured pose is used instead.
  double max_smoothing_deg = 5.0;
};

struct PoseEstimate {
  Pose pose;                        // T_cam_object
  double reprojection_rms_px = 0;   // sqrt of the mean squared corner distance (equation 6.2)
  double object_space_error = 0;    // Lu-Hager-Mjolsness object-space error (RPP)
  std::optional<Pose> alternative;  // the other local minimum of a planar target, when found
  double alternative_rms_px = 0;
};

// The corners of a square marker of side `side_m` in its own frame, TL TR BR BL.
std::array<cv::Point3d, 4> markerCorners(double side_m);

// `image` are ideal (undistorted) pixel coordinates of `object`, matched by index (at least 4;
// RPP and IPPE need the object points on the plane z = 0). Throws std::invalid_argument for
// mismatched or too few points.
PoseEstimate estimatePose(std::span<const cv::Point3d> object, std::span<const cv::Point2d> image,
                          const cv::Matx33d& camera_matrix, const PoseOptions& options = {});

// T_cam_world of a camera at `eye` looking at `target`, in a world whose z axis is up: the image's
// x axis points to the world's right, its y axis down. Looking straight down, x is the world's x.
Pose cameraLookingAt(const cv::Vec3d& eye, const cv::Vec3d& target);

// Projects `object` with `pose` and the ideal camera matrix.
cv::Point2d project(const Pose& pose, const cv::Matx33d& camera_matrix, const cv::Point3d& object);

}  // namespace arbci::vision
