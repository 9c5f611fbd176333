#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "arbci/vision/pose.h"

namespace arbci::vision {

Pose Pose::inverse() const {
  const cv::Matx33d rt = rotation.t();
  return {rt, -(rt * translation)};
}

Pose Pose::operator*(const Pose& other) const {
  return {rotation * other.rotation, rotation * other.translation + translation};
}

Pose Pose::fromRotationVector(const cv::Vec3d& rvec, const cv::Vec3d& t) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  return {r, t};
}

cv::Vec3d Pose::rotationVector() const {
  cv::Vec3d rvec;
  cv::Rodrigues(rotation, rvec);
  return rvec;
}

cv::Matx33d rotationFromQuaternion(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

double rotationAngleDeg(const cv::Matx33d& a, const cv::Matx33d& b) {
  const cv::Matx33d d = a.t() * b;
  const double c = std::clamp((d(0, 0) + d(1, 1) + d(2, 2) - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

std::string toString(PoseMethod method) {
  switch (method) {
    case PoseMethod::Rpp:
      return "rpp";
    case PoseMethod::Ippe:
      return "ippe";
    case PoseMethod::Iterative:
      return "iterative";
  }
  return "?";
}

PoseMethod poseMethodFromString(const std::string& text) {
  for (PoseMethod m : {PoseMethod::Rpp, PoseMethod::Ippe, PoseMethod::Iterative}) {
    if (toString(m) == text) return m;
  }
  throw std::invalid_argument("unknown pose method '" + text + "' (rpp, ippe, iterative)");
}

}  // namespace arbci::vision
