#include "posed_markers.h"

#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/vision/undistortion.h"

namespace arbci::test {

Corners drawPosedMarker(cv::Mat& frame, const cv::Matx33d& k, const vision::Pose& T_cam_marker,
                        double side_m, MarkerFamily family, int id) {
  // The printed image is 10 cells: the black square (8 cells) inside a 1-cell quiet zone.
  const double half = side_m / 2.0, outer = side_m * 10.0 / 8.0 / 2.0;
  const cv::Point3d black[4] = {
      {-half, half, 0}, {half, half, 0}, {half, -half, 0}, {-half, -half, 0}};
  const cv::Point3d quiet[4] = {
      {-outer, outer, 0}, {outer, outer, 0}, {outer, -outer, 0}, {-outer, -outer, 0}};
  Corners truth, outline;
  for (int c = 0; c < 4; ++c) {
    const cv::Point2d b = vision::project(T_cam_marker, k, black[c]);
    const cv::Point2d q = vision::project(T_cam_marker, k, quiet[c]);
    truth[c] = cv::Point2f(static_cast<float>(b.x), static_cast<float>(b.y));
    outline[c] = cv::Point2f(static_cast<float>(q.x), static_cast<float>(q.y));
  }
  drawWarped(frame, markerImage(family, id, 16), outline);
  return truth;
}

DistortingCamera::DistortingCamera(const vision::CameraModel& camera) {
  // Each pixel of the distorted image shows the ideal image at its undistorted position.
  const vision::Undistorter lens(camera, vision::UndistortMode::LookupTable);
  map_x_.create(camera.image_size, CV_32F);
  map_y_.create(camera.image_size, CV_32F);
  for (int y = 0; y < camera.image_size.height; ++y) {
    for (int x = 0; x < camera.image_size.width; ++x) {
      const cv::Point2d p = lens.undistort({static_cast<double>(x), static_cast<double>(y)});
      map_x_.at<float>(y, x) = static_cast<float>(p.x);
      map_y_.at<float>(y, x) = static_cast<float>(p.y);
    }
  }
}

cv::Mat DistortingCamera::operator()(const cv::Mat& ideal) const {
  cv::Mat distorted;
  cv::remap(ideal, distorted, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return distorted;
}

cv::Matx33d markerRotation(double tilt_deg, double azimuth_deg, double spin_deg) {
  const double deg = std::numbers::pi / 180.0;
  cv::Matx33d tilt, spin;
  cv::Rodrigues(
      cv::Vec3d(std::cos(azimuth_deg * deg), std::sin(azimuth_deg * deg), 0.0) * (tilt_deg * deg),
      tilt);
  cv::Rodrigues(cv::Vec3d(0.0, 0.0, spin_deg * deg), spin);
  // Facing the camera: the marker's z towards the camera (-z), its y up in the image (-y).
  return tilt * spin * cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1);
}

}  // namespace arbci::test
