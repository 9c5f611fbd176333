#include "arbci/vision/camera_model.h"

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>

#include "arbci/core/text.h"

namespace arbci::vision {
namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw CalibrationFileError(source + ": " + what);
}

cv::Mat readMatrix(const cv::FileNode& node, const std::string& source, const std::string& field) {
  if (node.empty()) fail(source, "missing field '" + field + "'");
  cv::Mat matrix;
  try {
    node >> matrix;
  } catch (const cv::Exception&) {
    fail(source, "field '" + field + "' is not a matrix");
  }
  if (matrix.empty()) fail(source, "field '" + field + "' is not a matrix");
  matrix.convertTo(matrix, CV_64F);
  return matrix;
}

int readInt(const cv::FileNode& node, const std::string& source, const std::string& field) {
  if (node.empty()) fail(source, "missing field '" + field + "'");
  if (!node.isInt() && !node.isReal()) fail(source, "field '" + field + "' is not a number");
  return static_cast<int>(node.real());
}

CameraModel readCamera(const cv::FileNode& root, const std::string& source,
                       const std::string& prefix = "") {
  CameraModel model;
  model.source = source;
  model.image_size.width = readInt(root[prefix + "image_width"], source, prefix + "image_width");
  model.image_size.height = readInt(root[prefix + "image_height"], source, prefix + "image_height");
  const cv::Mat k = readMatrix(root[prefix + "camera_matrix"], source, prefix + "camera_matrix");
  if (k.rows != 3 || k.cols != 3) fail(source, "field '" + prefix + "camera_matrix' must be 3x3");
  model.camera_matrix = cv::Matx33d(k);
  const cv::FileNode d = root[prefix + "distortion_coefficients"];
  if (!d.empty()) {
    const cv::Mat coefficients = readMatrix(d, source, prefix + "distortion_coefficients");
    model.distortion.assign(coefficients.begin<double>(), coefficients.end<double>());
  }
  if (!root[prefix + "avg_reprojection_error"].empty())
    model.rms_px = root[prefix + "avg_reprojection_error"].real();
  model.validate();
  return model;
}

// ARToolKitPlus_CamCal_Rev02: w h cx cy fx fy k1 k2 p1 p2 k3 (unused) iterations.
CameraModel readArToolKitPlus(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string tag;
  in >> tag;
  const std::string source = path.string();
  if (tag != "ARToolKitPlus_CamCal_Rev02") fail(source, "not an ARToolKitPlus_CamCal_Rev02 file");
  double w, h, cx, cy, fx, fy, k1, k2, p1, p2, k3;
  if (!(in >> w >> h >> cx >> cy >> fx >> fy >> k1 >> k2 >> p1 >> p2 >> k3)) {
    fail(source, "expected 'w h cx cy fx fy k1 k2 p1 p2 k3 ...' after the header");
  }
  CameraModel model;
  model.source = source;
  model.image_size = {static_cast<int>(w), static_cast<int>(h)};
  model.camera_matrix = cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  model.distortion = {k1, k2, p1, p2, k3};
  model.validate();
  return model;
}

void writeCamera(cv::FileStorage& out, const CameraModel& model, const std::string& prefix = "") {
  out << prefix + "image_width" << model.image_size.width;
  out << prefix + "image_height" << model.image_size.height;
  out << prefix + "camera_matrix" << cv::Mat(model.camera_matrix);
  out << prefix + "distortion_coefficients" << cv::Mat(model.distortion, true);
  if (model.rms_px >= 0.0) out << prefix + "avg_reprojection_error" << model.rms_px;
}

cv::FileStorage openForReading(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) fail(path.string(), "no such file");
  cv::FileStorage in;
  try {
    in.open(path.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    fail(path.string(), "not a valid OpenCV YAML/XML file (" + e.err + ")");
  }
  if (!in.isOpened()) fail(path.string(), "not a valid OpenCV YAML/XML file");
  return in;
}

cv::FileStorage openForWriting(const std::filesystem::path& path) {
  cv::FileStorage out;
  try {
    out.open(path.string(), cv::FileStorage::WRITE);
  } catch (const cv::Exception& e) {
    fail(path.string(), "cannot write (" + e.err + ")");
  }
  if (!out.isOpened()) fail(path.string(), "cannot write");
  return out;
}

}  // namespace

void CameraModel::validate() const {
  if (image_size.width <= 0 || image_size.height <= 0) {
    fail(source, "image size must be positive, got " + std::to_string(image_size.width) + "x" +
                     std::to_string(image_size.height));
  }
  if (!(fx() > 0.0) || !(fy() > 0.0)) {
    std::ostringstream text;
    text << "camera_matrix focal lengths must be positive, got fx " << fx() << ", fy " << fy();
    fail(source, text.str());
  }
  if (std::abs(camera_matrix(1, 0)) > 1e-9 || std::abs(camera_matrix(2, 0)) > 1e-9 ||
      std::abs(camera_matrix(2, 1)) > 1e-9 || std::abs(camera_matrix(2, 2) - 1.0) > 1e-9) {
    fail(source, "camera_matrix must be [fx s cx; 0 fy cy; 0 0 1]");
  }
  if (!(cx() >= 0.0 && cx() <= image_size.width && cy() >= 0.0 && cy() <= image_size.height)) {
    std::ostringstream text;
    text << "principal point (" << cx() << ", " << cy() << ") lies outside the " << image_size.width
         << "x" << image_size.height << " image";
    fail(source, text.str());
  }
  const size_t n = distortion.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    fail(source,
         "distortion_coefficients must have 4, 5, 8, 12 or 14 values, got " + std::to_string(n));
  }
  for (double d : distortion) {
    if (!std::isfinite(d)) fail(source, "distortion_coefficients contain a non-finite value");
  }
}

CameraModel CameraModel::scaledTo(cv::Size size) const {
  CameraModel scaled = *this;
  const double sx = static_cast<double>(size.width) / image_size.width;
  const double sy = static_cast<double>(size.height) / image_size.height;
  scaled.image_size = size;
  scaled.camera_matrix(0, 0) *= sx;
  scaled.camera_matrix(0, 1) *= sx;
  scaled.camera_matrix(0, 2) = (camera_matrix(0, 2) + 0.5) * sx - 0.5;
  scaled.camera_matrix(1, 1) *= sy;
  scaled.camera_matrix(1, 2) = (camera_matrix(1, 2) + 0.5) * sy - 0.5;
  return scaled;
}

void CameraModel::checkImageSize(cv::Size size) const {
  if (size == image_size) return;
  // A uniform scale of the sensor (e.g. 640x480 calibration, 320x240 frames) is accepted.
  if (size.width * image_size.height == size.height * image_size.width) return;
  fail(source, "frames are " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                   " but image_width x image_height is " + std::to_string(image_size.width) + "x" +
                   std::to_string(image_size.height));
}

CameraModel CameraModel::load(const std::filesystem::path& path) {
  if (core::lowerCase(path.extension().string()) == ".cal") {
    if (!std::filesystem::is_regular_file(path)) fail(path.string(), "no such file");
    return readArToolKitPlus(path);
  }
  cv::FileStorage in = openForReading(path);
  return readCamera(in.root(), path.string());
}

void CameraModel::save(const std::filesystem::path& path) const {
  cv::FileStorage out = openForWriting(path);
  writeCamera(out, *this);
}

StereoCameras StereoCameras::load(const std::filesystem::path& path) {
  cv::FileStorage in = openForReading(path);
  StereoCameras stereo;
  const std::string source = path.string();
  stereo.left = readCamera(in.root(), source, "left_");
  stereo.right = readCamera(in.root(), source, "right_");
  const cv::Mat r = readMatrix(in["R"], source, "R");
  const cv::Mat t = readMatrix(in["T"], source, "T");
  if (r.rows != 3 || r.cols != 3) fail(source, "field 'R' must be 3x3");
  if (t.total() != 3) fail(source, "field 'T' must have 3 values");
  stereo.rotation = cv::Matx33d(r);
  stereo.translation = cv::Vec3d(t.at<double>(0), t.at<double>(1), t.at<double>(2));
  if (!in["rms"].empty()) stereo.rms_px = in["rms"].real();
  return stereo;
}

void StereoCameras::save(const std::filesystem::path& path) const {
  cv::FileStorage out = openForWriting(path);
  writeCamera(out, left, "left_");
  writeCamera(out, right, "right_");
  out << "R" << cv::Mat(rotation) << "T" << cv::Mat(translation);
  if (rms_px >= 0.0) out << "rms" << rms_px;
}

}  // namespace arbci::vision
