#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "arbci/vision/pose.h"
#include "pose_refinement.h"
#include "rpp.h"

namespace arbci::vision {
namespace {

struct Candidate {
  Pose pose;
  double rms_px;
  double object_space_error;
};

double reprojectionRms(const Pose& pose, const cv::Matx33d& k, std::span<const cv::Point3d> object,
                       std::span<const cv::Point2d> image) {
  return std::sqrt(squaredReprojectionError(pose, k, object, image) /
                   static_cast<double>(object.size()));
}

bool planar(std::span<const cv::Point3d> object) {
  for (const cv::Point3d& p : object) {
    if (std::abs(p.z) > 1e-9) return false;
  }
  return true;
}

std::vector<Candidate> solve(std::span<const cv::Point3d> object,
                             std::span<const cv::Point2d> image, const cv::Matx33d& k,
                             PoseMethod method) {
  std::vector<Candidate> candidates;
  if (method == PoseMethod::Rpp) {
    std::vector<cv::Point2d> rays;
    for (const cv::Point2d& p : image)
      rays.emplace_back((p.x - k(0, 2)) / k(0, 0), (p.y - k(1, 2)) / k(1, 1));
    for (const RppSolution& s : robustPlanarPose(object, rays)) {
      candidates.push_back({{s.rotation, s.translation}, 0.0, s.object_space_error});
    }
    return candidates;
  }
  const std::vector<cv::Point3d> o(object.begin(), object.end());
  const std::vector<cv::Point2d> i(image.begin(), image.end());
  std::vector<cv::Mat> rvecs, tvecs;
  const bool square = object.size() == 4 && [&] {
    const double h = object[1].x;
    const std::array<cv::Point3d, 4> expected = markerCorners(2.0 * h);
    for (int c = 0; c < 4; ++c) {
      if (cv::norm(object[c] - expected[c]) > 1e-9) return false;
    }
    return true;
  }();
  const int flag = method == PoseMethod::Iterative ? cv::SOLVEPNP_ITERATIVE
                   : square                        ? cv::SOLVEPNP_IPPE_SQUARE
                                                   : cv::SOLVEPNP_IPPE;
  cv::solvePnPGeneric(o, i, k, cv::noArray(), rvecs, tvecs, false,
                      static_cast<cv::SolvePnPMethod>(flag));
  for (size_t s = 0; s < rvecs.size(); ++s) {
    const Pose pose = Pose::fromRotationVector(cv::Vec3d(rvecs[s]), cv::Vec3d(tvecs[s]));
    if (pose.translation[2] > 0.0) candidates.push_back({pose, 0.0, 0.0});
  }
  return candidates;
}

}  // namespace

std::array<cv::Point3d, 4> markerCorners(double side_m) {
  const double h = side_m / 2.0;
  return {cv::Point3d(-h, h, 0), cv::Point3d(h, h, 0), cv::Point3d(h, -h, 0),
          cv::Point3d(-h, -h, 0)};
}

Pose cameraLookingAt(const cv::Vec3d& eye, const cv::Vec3d& target) {
  const cv::Vec3d forward = cv::normalize(target - eye);
  cv::Vec3d right = forward.cross(cv::Vec3d(0, 0, 1));
  if (cv::norm(right) < 1e-9) right = cv::Vec3d(1, 0, 0);
  right = cv::normalize(right);
  const cv::Vec3d down = forward.cross(right);
  cv::Matx33d r;  // rows: the camera's axes in world coordinates
  for (int c = 0; c < 3; ++c) {
    r(0, c) = right[c];
    r(1, c) = down[c];
    r(2, c) = forward[c];
  }
  return Pose{r, -(r * eye)};
}

cv::Point2d project(const Pose& pose, const cv::Matx33d& k, const cv::Point3d& object) {
  const cv::Vec3d c = pose.apply(cv::Vec3d(object.x, object.y, object.z));
  return {k(0, 0) * c[0] / c[2] + k(0, 1) * c[1] / c[2] + k(0, 2), k(1, 1) * c[1] / c[2] + k(1, 2)};
}

PoseEstimate estimatePose(std::span<const cv::Point3d> object, std::span<const cv::Point2d> image,
                          const cv::Matx33d& k, const PoseOptions& options) {
  if (object.size() != image.size())
    throw std::invalid_argument("pose: object and image points differ in number");
  if (object.size() < 4) throw std::invalid_argument("pose: at least 4 points are needed");
  PoseMethod method = options.method;
  if (method != PoseMethod::Iterative && !planar(object)) method = PoseMethod::Iterative;
  std::vector<Candidate> candidates = solve(object, image, k, method);
  if (candidates.empty()) throw std::invalid_argument("pose: no solution in front of the camera");
  for (Candidate& c : candidates) {
    if (options.refine) c.pose = refineReprojection(c.pose, k, object, image);
    c.rms_px = reprojectionRms(c.pose, k, object, image);
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.rms_px < b.rms_px; });
  // Two solutions of near-equal error: follow the previous frame rather than the noise.
  if (candidates.size() > 1 && options.previous &&
      candidates[1].rms_px <= options.ambiguity_ratio * std::max(candidates[0].rms_px, 0.05) &&
      rotationAngleDeg(candidates[1].pose.rotation, options.previous->rotation) <
          rotationAngleDeg(candidates[0].pose.rotation, options.previous->rotation)) {
    std::swap(candidates[0], candidates[1]);
  }
  PoseEstimate estimate;
  estimate.pose = candidates[0].pose;
  estimate.reprojection_rms_px = candidates[0].rms_px;
  estimate.object_space_error = candidates[0].object_space_error;
  if (candidates.size() > 1 &&
      rotationAngleDeg(candidates[1].pose.rotation, candidates[0].pose.rotation) > 0.5) {
    estimate.alternative = candidates[1].pose;
    estimate.alternative_rms_px = candidates[1].rms_px;
  }
  return estimate;
}

}  // namespace arbci::vision
