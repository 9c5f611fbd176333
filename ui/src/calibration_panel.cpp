#include <imgui.h>

#include <cfloat>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "widgets.h"

namespace arbci::ui {

CalibrationPanel::CalibrationPanel(WorkstationModel& model)
    : model_(model), calibrator_(vision::CalibrationBoard{}) {
  reference_id_ = model.referenceId();
  const cv::Vec3d p = model.referencePosition();
  for (int i = 0; i < 3; ++i) reference_position_[i] = static_cast<float>(p[i]);
}

void CalibrationPanel::captureView() {
  const cv::Mat image = model_.cameraImage();
  if (image.empty()) return;
  const vision::ViewResult r =
      calibrator_.addView(image, "view " + std::to_string(calibrator_.viewCount() + 1));
  last_view_ = vision::toString(r.outcome) + (r.reason.empty() ? "" : ": " + r.reason);
  last_corners_ = r.corners;
  if (board_) model_.holdBoard(true);  // the next view from another pose
}

void CalibrationPanel::holdBoard(bool show) {
  board_ = show && model_.canHoldBoard();
  model_.holdBoard(board_);
}

void CalibrationPanel::calibrate() {
  try {
    result_ = calibrator_.calibrate();
    message_.clear();
  } catch (const std::exception& error) {
    message_ = error.what();
  }
}

void CalibrationPanel::draw() {
  const vision::CalibrationBoard& board = calibrator_.board();
  ImGui::Text("board: chessboard %dx%d inner corners, %.0f mm squares", board.inner_corners.width,
              board.inner_corners.height, board.square_m * 1000);
  if (model_.canHoldBoard()) {
    if (ImGui::Checkbox("hold the simulated board up", &board_)) model_.holdBoard(board_);
  }
  cv::Mat image = model_.cameraImage();
  if (button("Capture view", image.empty() ? "no camera image yet" : "")) captureView();
  ImGui::SameLine();
  ImGui::Text("%zu views; coverage %.0f%%", calibrator_.viewCount(),
              100.0 * calibrator_.coverageFraction());
  if (!last_view_.empty()) ImGui::Text("last view: %s", last_view_.c_str());
  if (button("Calibrate", calibrator_.viewCount() < 3 ? "capture at least 3 views first" : ""))
    calibrate();
  if (result_) {
    pathInput("calibration file (.yml, .xml)", save_path_, sizeof save_path_, ".yml .yaml .xml",
              "where Save writes the camera's calibration (OpenCV YAML or XML)");
    if (button("Save")) {
      try {
        result_->camera.save(save_path_);
        message_ = std::string("saved ") + save_path_;
      } catch (const std::exception& error) {
        message_ = error.what();
      }
    }
    ImGui::Text("overall RMS %.3f px; fx %.1f fy %.1f cx %.1f cy %.1f", result_->rms_px,
                result_->camera.fx(), result_->camera.fy(), result_->camera.cx(),
                result_->camera.cy());
    for (size_t i = 0; i < result_->per_view_rms_px.size(); ++i) {
      ImGui::Text("  %s: %.3f px", result_->view_names[i].c_str(), result_->per_view_rms_px[i]);
    }
    ImGui::Checkbox("preview undistorted", &preview_undistorted_);
  }
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());

  // The live image with what the detector finds in it, or its undistorted preview.
  cv::Mat shown;
  if (!image.empty()) {
    if (preview_undistorted_ && result_) {
      cv::undistort(image, shown, result_->camera.camera_matrix, result_->camera.distortion);
    } else {
      shown = image.clone();
      std::vector<cv::Point2f> corners;
      cv::Mat grey;
      cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
      const bool found =
          cv::findChessboardCorners(grey, board.inner_corners, corners,
                                    cv::CALIB_CB_FAST_CHECK | cv::CALIB_CB_ADAPTIVE_THRESH);
      cv::drawChessboardCorners(shown, board.inner_corners, corners, found);
      if (!found)
        cv::putText(shown, "no board in view", {10, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.8,
                    cv::Scalar(0, 0, 255), 2);
    }
  }
  const float width = ImGui::GetContentRegionAvail().x * 0.62f;
  view_.draw(shown, width);
  ImGui::SameLine();
  // Coverage: cells where corners were seen, brighter for more.
  const cv::Mat counts = calibrator_.coverage();
  cv::Mat map(counts.rows * 20, counts.cols * 20, CV_8UC3, cv::Scalar(40, 40, 40));
  if (calibrator_.viewCount() > 0) {
    for (int y = 0; y < counts.rows; ++y) {
      for (int x = 0; x < counts.cols; ++x) {
        const int n = counts.at<int>(y, x);
        if (n > 0)
          map(cv::Rect(x * 20, y * 20, 19, 19))
              .setTo(cv::Scalar(40, std::min(255, 90 + 25 * n), 40));
      }
    }
  }
  ImGui::BeginGroup();
  ImGui::TextUnformatted("coverage");
  coverage_.draw(map, ImGui::GetContentRegionAvail().x);
  ImGui::EndGroup();

  heading("reference marker (robot frame)");
  ImGui::TextUnformatted("marker id");
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::InputInt("##id", &reference_id_);
  ImGui::TextUnformatted("position in the robot frame (m)");
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::InputFloat3("##position", reference_position_, "%.3f");
  if (button("Apply reference")) {
    model_.setReference(reference_id_, cv::Vec3d(reference_position_[0], reference_position_[1],
                                                 reference_position_[2]));
  }
}

PanelRegistry::Entry calibrationPanel() {
  return {
      "calibration",
      "camera calibration from chessboard views, and the reference marker",
      {[](const PanelContext& c) { return std::make_unique<CalibrationPanel>(c.model); }, false}};
}

}  // namespace arbci::ui
