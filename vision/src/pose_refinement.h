// Private: Levenberg-Marquardt on the reprojection error (the seed's equation 6.2) of a pose,
// with the analytic Jacobian of the pinhole projection (six parameters: a rotation increment
// applied on the left and the translation).
#pragma once

#include <span>

#include "arbci/vision/pose.h"

namespace arbci::vision {

// The sum of squared distances between `image` and the projections of `object`, px^2.
double squaredReprojectionError(const Pose& pose, const cv::Matx33d& camera_matrix,
                                std::span<const cv::Point3d> object,
                                std::span<const cv::Point2d> image);

Pose refineReprojection(const Pose& start, const cv::Matx33d& camera_matrix,
                        std::span<const cv::Point3d> object, std::span<const cv::Point2d> image);

}  // namespace arbci::vision
