#include "arbci/vision/calibration.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "dictionary_detector.h"

namespace arbci::vision {
namespace {

cv::Mat toGray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  return gray;
}

int flagsOf(const CalibrationFlags& flags) {
  int f = 0;
  if (flags.fix_aspect_ratio) f |= cv::CALIB_FIX_ASPECT_RATIO;
  if (flags.zero_tangential) f |= cv::CALIB_ZERO_TANGENT_DIST;
  if (flags.fix_k3) f |= cv::CALIB_FIX_K3;
  return f;
}

cv::Ptr<cv::aruco::CharucoBoard> charucoBoard(const CalibrationBoard& board) {
  return cv::aruco::CharucoBoard::create(
      board.squares.width, board.squares.height, static_cast<float>(board.square_m),
      static_cast<float>(board.marker_m),
      cv::aruco::getPredefinedDictionary(dictionaryId(board.dictionary)));
}

std::vector<cv::Point3f> chessboardPoints(const CalibrationBoard& board) {
  std::vector<cv::Point3f> points;
  for (int r = 0; r < board.inner_corners.height; ++r) {
    for (int c = 0; c < board.inner_corners.width; ++c) {
      points.emplace_back(static_cast<float>(c * board.square_m),
                          static_cast<float>(r * board.square_m), 0.0f);
    }
  }
  return points;
}

}  // namespace

std::string toString(ViewOutcome outcome) {
  switch (outcome) {
    case ViewOutcome::Accepted:
      return "accepted";
    case ViewOutcome::NoBoard:
      return "no board";
    case ViewOutcome::Blurred:
      return "blurred";
    case ViewOutcome::Duplicate:
      return "duplicate";
    case ViewOutcome::WrongSize:
      return "wrong size";
  }
  return "?";
}

IncrementalCalibrator::IncrementalCalibrator(CalibrationBoard board) : board_(std::move(board)) {
  if (board_.square_m <= 0.0)
    throw std::invalid_argument("calibration board: square size must be positive");
  if (board_.kind == CalibrationBoard::Kind::Chessboard &&
      (board_.inner_corners.width < 3 || board_.inner_corners.height < 3)) {
    throw std::invalid_argument("calibration board: at least 3x3 inner corners");
  }
  if (board_.kind == CalibrationBoard::Kind::Charuco) {
    dictionaryId(board_.dictionary);  // throws for an unknown name
    if (!(board_.marker_m > 0.0 && board_.marker_m < board_.square_m)) {
      throw std::invalid_argument(
          "calibration board: ChArUco markers must be smaller than the squares");
    }
  }
}

std::optional<IncrementalCalibrator::View> IncrementalCalibrator::detect(const cv::Mat& gray,
                                                                         ViewResult& result) const {
  View view;
  if (board_.kind == CalibrationBoard::Kind::Chessboard) {
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(gray, board_.inner_corners, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      result = {ViewOutcome::NoBoard,
                "no " + std::to_string(board_.inner_corners.width) + "x" +
                    std::to_string(board_.inner_corners.height) + " chessboard found",
                {}};
      return std::nullopt;
    }
    cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01));
    view.image_points = corners;
    view.object_points = chessboardPoints(board_);
    // Edge sharpness as OpenCV measures it on chessboards (mean edge width in pixels).
    const cv::Scalar sharpness =
        cv::estimateChessboardSharpness(gray, board_.inner_corners, corners);
    if (sharpness[0] > max_edge_width_px) {
      std::ostringstream reason;
      reason.precision(2);
      reason << std::fixed << "blurred: edges " << sharpness[0] << " px wide (at most "
             << max_edge_width_px << ")";
      result = {ViewOutcome::Blurred, reason.str(), corners};
      return std::nullopt;
    }
  } else {
    const auto board = charucoBoard(board_);
    std::vector<std::vector<cv::Point2f>> marker_corners;
    std::vector<int> marker_ids;
    cv::aruco::detectMarkers(gray, board->dictionary, marker_corners, marker_ids);
    std::vector<cv::Point2f> corners;
    std::vector<int> ids;
    if (!marker_ids.empty()) {
      cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, board, corners, ids);
    }
    if (ids.size() < 6) {
      result = {ViewOutcome::NoBoard, "fewer than 6 ChArUco corners found", corners};
      return std::nullopt;
    }
    view.image_points = corners;
    view.ids = ids;
    for (int id : ids) view.object_points.push_back(board->chessboardCorners[id]);
  }
  return view;
}

ViewResult IncrementalCalibrator::addView(const cv::Mat& image, const std::string& name) {
  ViewResult result;
  if (image.empty()) {
    result.reason = "empty image";
    return result;
  }
  if (!views_.empty() && image.size() != image_size_) {
    result.outcome = ViewOutcome::WrongSize;
    result.reason = "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                    ", the views so far " + std::to_string(image_size_.width) + "x" +
                    std::to_string(image_size_.height);
    return result;
  }
  const cv::Mat gray = toGray(image);
  std::optional<View> view = detect(gray, result);
  if (!view) return result;
  // A duplicate: every corner within a few pixels of an earlier view's (same ids).
  for (const View& earlier : views_) {
    if (earlier.image_points.size() != view->image_points.size() || earlier.ids != view->ids)
      continue;
    double sum = 0.0;
    for (size_t i = 0; i < view->image_points.size(); ++i)
      sum += cv::norm(view->image_points[i] - earlier.image_points[i]);
    if (sum / static_cast<double>(view->image_points.size()) < min_new_view_px) {
      return {ViewOutcome::Duplicate, "too like view '" + earlier.name + "'", view->image_points};
    }
  }
  view->name = name.empty() ? "view " + std::to_string(views_.size() + 1) : name;
  image_size_ = image.size();
  views_.push_back(*view);
  return {ViewOutcome::Accepted, "", view->image_points};
}

cv::Mat IncrementalCalibrator::coverage(cv::Size grid) const {
  cv::Mat counts(grid, CV_32S, cv::Scalar(0));
  if (image_size_.area() == 0) return counts;
  for (const View& view : views_) {
    for (const cv::Point2f& p : view.image_points) {
      const int gx =
          std::clamp(static_cast<int>(p.x * grid.width / image_size_.width), 0, grid.width - 1);
      const int gy =
          std::clamp(static_cast<int>(p.y * grid.height / image_size_.height), 0, grid.height - 1);
      ++counts.at<int>(gy, gx);
    }
  }
  return counts;
}

double IncrementalCalibrator::coverageFraction(cv::Size grid) const {
  const cv::Mat counts = coverage(grid);
  return static_cast<double>(cv::countNonZero(counts)) / counts.total();
}

CalibrationResult IncrementalCalibrator::calibrate(const CalibrationFlags& flags) const {
  if (views_.size() < 3) {
    throw std::runtime_error("calibration needs at least 3 accepted views, have " +
                             std::to_string(views_.size()));
  }
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const View& view : views_) {
    object.push_back(view.object_points);
    image.push_back(view.image_points);
  }
  cv::Mat k = cv::Mat::eye(3, 3, CV_64F), distortion, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(object, image, image_size_, k, distortion, rvecs, tvecs,
                                         cv::noArray(), cv::noArray(), per_view, flagsOf(flags));
  CalibrationResult result;
  result.camera.image_size = image_size_;
  result.camera.camera_matrix = cv::Matx33d(k);
  result.camera.distortion.assign(distortion.begin<double>(), distortion.end<double>());
  result.camera.rms_px = rms;
  result.camera.source = "calibration";
  result.rms_px = rms;
  result.per_view_rms_px.assign(per_view.begin<double>(), per_view.end<double>());
  for (const View& view : views_) result.view_names.push_back(view.name);
  return result;
}

StereoResult calibrateStereo(const CalibrationBoard& board, const std::vector<cv::Mat>& left,
                             const std::vector<cv::Mat>& right, const CalibrationFlags& flags) {
  if (left.size() != right.size())
    throw std::runtime_error("stereo calibration needs as many left as right views");
  if (board.kind != CalibrationBoard::Kind::Chessboard) {
    throw std::runtime_error("stereo calibration takes chessboard views");
  }
  IncrementalCalibrator left_calibrator(board), right_calibrator(board);
  left_calibrator.min_new_view_px = right_calibrator.min_new_view_px = 0.0;
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> left_points, right_points;
  for (size_t i = 0; i < left.size(); ++i) {
    const ViewResult l = left_calibrator.addView(left[i]);
    const ViewResult r = right_calibrator.addView(right[i]);
    if (l.outcome != ViewOutcome::Accepted || r.outcome != ViewOutcome::Accepted) continue;
    left_points.push_back(l.corners);
    right_points.push_back(r.corners);
    object.push_back(chessboardPoints(board));
  }
  if (object.size() < 3)
    throw std::runtime_error(
        "stereo calibration needs at least 3 pairs with the board in both views");
  const CalibrationResult l = left_calibrator.calibrate(flags),
                          r = right_calibrator.calibrate(flags);
  cv::Mat kl(l.camera.camera_matrix), kr(r.camera.camera_matrix), dl(l.camera.distortion, true),
      dr(r.camera.distortion, true);
  cv::Mat rotation, translation, essential, fundamental;
  const double rms = cv::stereoCalibrate(object, left_points, right_points, kl, dl, kr, dr,
                                         left_calibrator.imageSize(), rotation, translation,
                                         essential, fundamental, cv::CALIB_FIX_INTRINSIC);
  StereoResult result;
  result.cameras.left = l.camera;
  result.cameras.right = r.camera;
  result.cameras.rotation = cv::Matx33d(rotation);
  result.cameras.translation = cv::Vec3d(translation);
  result.cameras.rms_px = rms;
  result.rms_px = rms;
  result.pairs = static_cast<int>(object.size());
  return result;
}

}  // namespace arbci::vision
