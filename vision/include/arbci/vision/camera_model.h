// A calibrated camera: pinhole intrinsics with OpenCV's radial/tangential distortion model, for
// one camera or a stereo pair. Read and written in OpenCV's YAML/XML calibration format (the keys
// of OpenCV's calibration sample: image_width, image_height, camera_matrix,
// distortion_coefficients, ...) so files from OpenCV's tools work unchanged; ARToolKitPlus .cal
// files are read too.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/matx.hpp>

namespace arbci::vision {

// A calibration or configuration file that cannot be used; the message names the file and field.
class CalibrationFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CameraModel {
  cv::Size image_size;
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion;  // k1 k2 p1 p2 [k3 [k4 k5 k6]]; empty = none
  double rms_px = -1.0;            // calibration reprojection error, when known
  std::string source;              // where it was read from (for messages)

  double fx() const { return camera_matrix(0, 0); }
  double fy() const { return camera_matrix(1, 1); }
  double cx() const { return camera_matrix(0, 2); }
  double cy() const { return camera_matrix(1, 2); }

  // Throws CalibrationFileError naming `source` and the offending field.
  void validate() const;
  // The same camera for another image size (a scaled sensor readout: intrinsics scale, distortion
  // does not).
  CameraModel scaledTo(cv::Size size) const;
  // Throws CalibrationFileError when frames of `size` do not come from this camera's sensor size.
  void checkImageSize(cv::Size size) const;

  static CameraModel load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;
};

// Two cameras with the right camera's pose in the left camera's frame: x_right = R x_left + T.
struct StereoCameras {
  CameraModel left, right;
  cv::Matx33d rotation = cv::Matx33d::eye();
  cv::Vec3d translation;  // metres
  double rms_px = -1.0;

  static StereoCameras load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;
};

}  // namespace arbci::vision
