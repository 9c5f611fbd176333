#include "pose_refinement.h"

#include <Eigen/Dense>
#include <cmath>

#include <opencv2/calib3d.hpp>

namespace arbci::vision {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

}  // namespace

double squaredReprojectionError(const Pose& pose, const cv::Matx33d& k,
                                std::span<const cv::Point3d> object,
                                std::span<const cv::Point2d> image) {
  double sum = 0.0;
  for (size_t i = 0; i < object.size(); ++i) {
    const cv::Point2d d = project(pose, k, object[i]) - image[i];
    sum += d.dot(d);
  }
  return sum;
}

Pose refineReprojection(const Pose& start, const cv::Matx33d& k,
                        std::span<const cv::Point3d> object, std::span<const cv::Point2d> image) {
  Pose pose = start;
  double current = squaredReprojectionError(pose, k, object, image);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 20; ++iteration) {
    Matrix6d normal = Matrix6d::Zero();
    Vector6d gradient = Vector6d::Zero();
    for (size_t i = 0; i < object.size(); ++i) {
      const cv::Vec3d rotated = pose.rotation * cv::Vec3d(object[i].x, object[i].y, object[i].z);
      const cv::Vec3d c = rotated + pose.translation;
      if (c[2] <= 1e-9) return start;
      const double z_inv = 1.0 / c[2];
      const double u = k(0, 0) * c[0] * z_inv + k(0, 1) * c[1] * z_inv + k(0, 2);
      const double v = k(1, 1) * c[1] * z_inv + k(1, 2);
      // d(u, v) / d(point in camera frame)
      Eigen::Matrix<double, 2, 3> dp;
      dp << k(0, 0) * z_inv, k(0, 1) * z_inv, -(k(0, 0) * c[0] + k(0, 1) * c[1]) * z_inv * z_inv,
          0.0, k(1, 1) * z_inv, -k(1, 1) * c[1] * z_inv * z_inv;
      // d(point) / d(rotation increment w) = -[R p]x; d(point) / d(t) = I.
      Eigen::Matrix3d skew;
      skew << 0, rotated[2], -rotated[1], -rotated[2], 0, rotated[0], rotated[1], -rotated[0], 0;
      Eigen::Matrix<double, 2, 6> j;
      j.leftCols<3>() = dp * skew;
      j.rightCols<3>() = dp;
      const Eigen::Vector2d r(u - image[i].x, v - image[i].y);
      normal += j.transpose() * j;
      gradient += j.transpose() * r;
    }
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Matrix6d damped = normal;
      damped.diagonal() *= 1.0 + lambda;
      const Vector6d step = damped.ldlt().solve(-gradient);
      cv::Matx33d increment;
      cv::Rodrigues(cv::Vec3d(step(0), step(1), step(2)), increment);
      const Pose candidate{increment * pose.rotation,
                           pose.translation + cv::Vec3d(step(3), step(4), step(5))};
      const double candidate_cost = squaredReprojectionError(candidate, k, object, image);
      if (candidate_cost < current) {
        improved = true;
        const bool converged = current - candidate_cost < 1e-12 * (1.0 + current);
        pose = candidate;
        current = candidate_cost;
        lambda = std::max(1e-9, lambda * 0.1);
        if (converged) return pose;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return pose;
}

}  // namespace arbci::vision
