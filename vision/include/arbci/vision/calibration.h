// Camera calibration from chessboard or ChArUco views, incrementally as the calibration panel
// works: add views one by one (blurred, board-less and duplicate views are rejected with the
// reason), watch the coverage of the image, calibrate when asked (intrinsics, distortion, per-view
// and overall reprojection error). Stereo calibration of the two HMD cameras from paired views.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/camera_model.h"

namespace arbci::vision {

struct CalibrationBoard {
  enum class Kind { Chessboard, Charuco };
  Kind kind = Kind::Chessboard;
  cv::Size inner_corners{9, 6};  // chessboard: inner corners per row and column
  cv::Size squares{5, 7};        // ChArUco: squares per row and column
  double square_m = 0.025;
  double marker_m = 0.0125;                 // ChArUco marker side
  std::string dictionary = "DICT_6X6_250";  // ChArUco dictionary
};

enum class ViewOutcome { Accepted, NoBoard, Blurred, Duplicate, WrongSize };
std::string toString(ViewOutcome outcome);

struct ViewResult {
  ViewOutcome outcome = ViewOutcome::NoBoard;
  std::string reason;                // for the experimenter, e.g. "edges 4.1 px wide (max 3.5)"
  std::vector<cv::Point2f> corners;  // what was detected, for the overlay (empty if none)
};

struct CalibrationResult {
  CameraModel camera;
  double rms_px = 0.0;
  std::vector<double> per_view_rms_px;
  std::vector<std::string> view_names;
};

struct CalibrationFlags {
  bool fix_aspect_ratio = false;
  bool zero_tangential = false;
  bool fix_k3 = false;
};

class IncrementalCalibrator {
 public:
  explicit IncrementalCalibrator(CalibrationBoard board);

  // Detects the board in a grey or colour image; adds the view when it is usable.
  ViewResult addView(const cv::Mat& image, const std::string& name = "");
  size_t viewCount() const { return views_.size(); }
  // Corners seen per cell of a `grid` over the image (CV_32S), for the coverage map.
  cv::Mat coverage(cv::Size grid = {8, 6}) const;
  // Fraction of the grid's cells in which corners have been seen.
  double coverageFraction(cv::Size grid = {8, 6}) const;
  // Needs at least 3 views. Throws std::runtime_error with the reason otherwise.
  CalibrationResult calibrate(const CalibrationFlags& flags = {}) const;

  const CalibrationBoard& board() const { return board_; }
  cv::Size imageSize() const { return image_size_; }

  // Largest edge width (px) a view may have; wider means blurred.
  double max_edge_width_px = 3.5;
  // Mean corner displacement (px) below which a view duplicates an earlier one.
  double min_new_view_px = 8.0;

 private:
  struct View {
    std::string name;
    std::vector<cv::Point2f> image_points;
    std::vector<cv::Point3f> object_points;
    std::vector<int> ids;  // ChArUco corner ids
  };
  std::optional<View> detect(const cv::Mat& gray, ViewResult& result) const;
  CalibrationBoard board_;
  cv::Size image_size_;
  std::vector<View> views_;
};

struct StereoResult {
  StereoCameras cameras;
  double rms_px = 0.0;
  int pairs = 0;
};

// Calibrates each camera, then the pair, from views taken at the same moments (by index). Views
// where either camera misses the board are skipped. Throws std::runtime_error with the reason.
StereoResult calibrateStereo(const CalibrationBoard& board, const std::vector<cv::Mat>& left,
                             const std::vector<cv::Mat>& right, const CalibrationFlags& flags = {});

}  // namespace arbci::vision
