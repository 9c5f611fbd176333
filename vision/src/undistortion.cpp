#include "arbci/vision/undistortion.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace arbci::vision {
namespace {

// OpenCV's distortion model on normalised coordinates.
cv::Point2d distortNormalised(cv::Point2d p, const std::vector<double>& d) {
  auto at = [&](size_t i) { return i < d.size() ? d[i] : 0.0; };
  const double k1 = at(0), k2 = at(1), p1 = at(2), p2 = at(3), k3 = at(4), k4 = at(5), k5 = at(6),
               k6 = at(7);
  const double s1 = at(8), s2 = at(9), s3 = at(10), s4 = at(11);
  const double r2 = p.x * p.x + p.y * p.y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial = (1.0 + k1 * r2 + k2 * r4 + k3 * r6) / (1.0 + k4 * r2 + k5 * r4 + k6 * r6);
  return {p.x * radial + 2.0 * p1 * p.x * p.y + p2 * (r2 + 2.0 * p.x * p.x) + s1 * r2 + s2 * r4,
          p.y * radial + p1 * (r2 + 2.0 * p.y * p.y) + 2.0 * p2 * p.x * p.y + s3 * r2 + s4 * r4};
}

}  // namespace

std::string toString(UndistortMode mode) {
  switch (mode) {
    case UndistortMode::None:
      return "none";
    case UndistortMode::Algorithmic:
      return "algorithmic";
    case UndistortMode::LookupTable:
      return "lut";
  }
  return "?";
}

UndistortMode undistortModeFromString(const std::string& text) {
  for (UndistortMode m :
       {UndistortMode::None, UndistortMode::Algorithmic, UndistortMode::LookupTable}) {
    if (toString(m) == text) return m;
  }
  throw std::invalid_argument("unknown undistortion mode '" + text + "' (none, algorithmic, lut)");
}

Undistorter::Undistorter(const CameraModel& camera, UndistortMode mode)
    : camera_(camera), mode_(mode) {
  camera_.validate();
  for (double d : camera_.distortion) distorted_ = distorted_ || d != 0.0;
  if (mode_ != UndistortMode::LookupTable || !distorted_) return;
  const cv::Size size = camera_.image_size;
  ideal_of_pixel_.create(size, CV_32FC2);
  for (int y = 0; y < size.height; ++y) {
    cv::Vec2f* row = ideal_of_pixel_.ptr<cv::Vec2f>(y);
    cv::Point2d start(-1.0, -1.0);
    for (int x = 0; x < size.width; ++x) {
      // The neighbour's answer starts Newton's method a fraction of a pixel from this one's.
      const cv::Point2d ideal =
          undistortAlgorithmic({static_cast<double>(x), static_cast<double>(y)}, start);
      row[x] = cv::Vec2f(static_cast<float>(ideal.x), static_cast<float>(ideal.y));
      start = ideal + cv::Point2d(1.0, 0.0);
    }
  }
  cv::initUndistortRectifyMap(camera_.camera_matrix, camera_.distortion, cv::Matx33d::eye(),
                              camera_.camera_matrix, size, CV_16SC2, remap_xy_, remap_weights_);
}

cv::Point2d Undistorter::undistortAlgorithmic(cv::Point2d image_px, cv::Point2d start_px) const {
  const cv::Point2d target((image_px.x - camera_.cx()) / camera_.fx(),
                           (image_px.y - camera_.cy()) / camera_.fy());
  // Newton's method on distort(x) = target, with a numerical Jacobian; from `start_px` when given,
  // else from the distorted point itself.
  cv::Point2d x = start_px.x < 0.0 ? target
                                   : cv::Point2d((start_px.x - camera_.cx()) / camera_.fx(),
                                                 (start_px.y - camera_.cy()) / camera_.fy());
  for (int iteration = 0; iteration < 30; ++iteration) {
    const cv::Point2d f = distortNormalised(x, camera_.distortion) - target;
    if (f.x * f.x + f.y * f.y < 1e-24) break;
    constexpr double h = 1e-7;
    const cv::Point2d dx = (distortNormalised({x.x + h, x.y}, camera_.distortion) -
                            distortNormalised({x.x - h, x.y}, camera_.distortion)) /
                           (2 * h);
    const cv::Point2d dy = (distortNormalised({x.x, x.y + h}, camera_.distortion) -
                            distortNormalised({x.x, x.y - h}, camera_.distortion)) /
                           (2 * h);
    const double det = dx.x * dy.y - dy.x * dx.y;
    if (std::abs(det) < 1e-12) break;
    x.x -= (dy.y * f.x - dy.x * f.y) / det;
    x.y -= (-dx.y * f.x + dx.x * f.y) / det;
  }
  return {x.x * camera_.fx() + camera_.cx(), x.y * camera_.fy() + camera_.cy()};
}

cv::Point2d Undistorter::undistort(cv::Point2d image_px) const {
  if (mode_ == UndistortMode::None || !distorted_) return image_px;
  if (mode_ == UndistortMode::Algorithmic) return undistortAlgorithmic(image_px);
  // Bilinear interpolation in the table; outside it, the algorithmic answer.
  const double x = image_px.x, y = image_px.y;
  if (!(x >= 0.0 && y >= 0.0 && x <= ideal_of_pixel_.cols - 1.0 &&
        y <= ideal_of_pixel_.rows - 1.0)) {
    return undistortAlgorithmic(image_px);
  }
  const int x0 = std::min(static_cast<int>(x), ideal_of_pixel_.cols - 2);
  const int y0 = std::min(static_cast<int>(y), ideal_of_pixel_.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const cv::Vec2f* r0 = ideal_of_pixel_.ptr<cv::Vec2f>(y0) + x0;
  const cv::Vec2f* r1 = ideal_of_pixel_.ptr<cv::Vec2f>(y0 + 1) + x0;
  const cv::Vec2d top = cv::Vec2d(r0[0]) * (1 - fx) + cv::Vec2d(r0[1]) * fx;
  const cv::Vec2d bottom = cv::Vec2d(r1[0]) * (1 - fx) + cv::Vec2d(r1[1]) * fx;
  const cv::Vec2d ideal = top * (1 - fy) + bottom * fy;
  return {ideal[0], ideal[1]};
}

cv::Point2d Undistorter::distort(cv::Point2d ideal_px) const {
  if (!distorted_ || mode_ == UndistortMode::None) return ideal_px;
  const cv::Point2d n((ideal_px.x - camera_.cx()) / camera_.fx(),
                      (ideal_px.y - camera_.cy()) / camera_.fy());
  const cv::Point2d d = distortNormalised(n, camera_.distortion);
  return {d.x * camera_.fx() + camera_.cx(), d.y * camera_.fy() + camera_.cy()};
}

void Undistorter::undistortImage(const cv::Mat& image, cv::Mat& ideal) const {
  if (mode_ == UndistortMode::None || !distorted_) {
    image.copyTo(ideal);
    return;
  }
  camera_.checkImageSize(image.size());
  if (mode_ == UndistortMode::LookupTable && image.size() == camera_.image_size) {
    cv::remap(image, ideal, remap_xy_, remap_weights_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    return;
  }
  const CameraModel camera = camera_.scaledTo(image.size());
  cv::undistort(image, ideal, camera.camera_matrix, camera.distortion);
}

}  // namespace arbci::vision
