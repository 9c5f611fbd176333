// Lens undistortion in ARToolKitPlus's three modes, for points and whole images:
//  - None: identity;
//  - Algorithmic: each point solved from the distortion model (Newton's method to convergence);
//    images remapped through maps computed for the call;
//  - LookupTable: the ideal position of every pixel computed once for the image size (points are
//    interpolated bilinearly between pixels), and images remapped through precomputed
//    fixed-point maps -- the fastest for whole images.
// "Ideal" coordinates are pixels of the same camera matrix without distortion.
#pragma once

#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/camera_model.h"

namespace arbci::vision {

enum class UndistortMode { None, Algorithmic, LookupTable };

std::string toString(UndistortMode mode);
UndistortMode undistortModeFromString(const std::string& text);  // none, algorithmic, lut

class Undistorter {
 public:
  Undistorter(const CameraModel& camera, UndistortMode mode);

  cv::Point2d undistort(cv::Point2d image_px) const;
  // The forward model: where an ideal point appears in the image.
  cv::Point2d distort(cv::Point2d ideal_px) const;
  void undistortImage(const cv::Mat& image, cv::Mat& ideal) const;

  UndistortMode mode() const { return mode_; }
  const CameraModel& camera() const { return camera_; }

 private:
  cv::Point2d undistortAlgorithmic(cv::Point2d image_px, cv::Point2d start_px = {-1.0, -1.0}) const;
  CameraModel camera_;
  UndistortMode mode_;
  bool distorted_ = false;  // false when the camera has no distortion
  cv::Mat ideal_of_pixel_;  // LookupTable: CV_32FC2, the ideal position of each pixel centre
  cv::Mat remap_xy_, remap_weights_;  // LookupTable: cv::remap maps (CV_16SC2, CV_16UC1)
};

}  // namespace arbci::vision
