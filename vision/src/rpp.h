// Private: Robust Planar Pose (Schweighofer & Pinz 2006) on normalised image rays.
//  1. Orthogonal iteration (Lu, Hager & Mjolsness 2000) from a homography start gives a pose.
//  2. With the line of sight turned onto z, the rotation is written Rz(gamma) Ry(beta) Rz(alpha);
//     with the optimal translation for each rotation, the object-space error along beta is
//     exactly a quadratic form in (cos beta, sin beta), whose stationary points are the roots of a
//     quartic in tan(beta / 2). Every minimum is refined by orthogonal iteration; both planar
//     solutions come back, best first.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include <opencv2/core/matx.hpp>
#include <opencv2/core/types.hpp>

namespace arbci::vision {

struct RppSolution {
  cv::Matx33d rotation;
  cv::Vec3d translation;
  double object_space_error;
};

// `object` on the plane z = 0; `rays` are normalised image points (x, y) with z = 1.
// Returns one or two solutions, the smaller object-space error first.
std::vector<RppSolution> robustPlanarPose(std::span<const cv::Point3d> object,
                                          std::span<const cv::Point2d> rays);

}  // namespace arbci::vision
