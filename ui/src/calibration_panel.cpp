// The camera Calibration panel: chessboard views with a live detection overlay, the coverage
// map, per-view and overall reprojection error, calibrate and save, an undistortion preview, and
// the reference marker's place in the robot frame.
#include <imgui.h>

#include <cfloat>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "arbci/ui/image_view.h"
#include "arbci/ui/panel_registry.h"
#include "arbci/vision/calibration.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

class CalibrationPanel final : public Panel {
 public:
  CalibrationPanel() : calibrator_(vision::CalibrationBoard{}) {}
  const char* title() const override { return "Camera calibration"; }
  void draw(const PanelInput& in) override;
  // What the buttons do, also for a screenshot's recipe.
  void captureView(const PanelInput& in);
  void calibrate();
  void holdBoard(const PanelInput& in, bool show);

 private:
  void results();
  void liveImage(const cv::Mat& image);
  void reference(const PanelInput& in);
  vision::IncrementalCalibrator calibrator_;
  std::optional<vision::CalibrationResult> result_;
  std::string last_view_, message_;
  std::vector<cv::Point2f> last_corners_;
  char save_path_[256] = "camera.yml";
  bool preview_undistorted_ = false, board_ = false;
  bool reference_read_ = false;
  int reference_id_ = 0;
  float reference_position_[3] = {0.0f, 0.9f, 0.0f};
  ImageView view_, coverage_;
};

void CalibrationPanel::captureView(const PanelInput& in) {
  const cv::Mat& image = in.record.tracking.left_image;
  if (image.empty()) return;
  const vision::ViewResult r =
      calibrator_.addView(image, "view " + std::to_string(calibrator_.viewCount() + 1));
  last_view_ = vision::toString(r.outcome) + (r.reason.empty() ? "" : ": " + r.reason);
  last_corners_ = r.corners;
  // The next view from another pose.
  if (board_) in.requests.post(session::HoldBoardRequest{true});
}

void CalibrationPanel::holdBoard(const PanelInput& in, bool show) {
  board_ = show && in.record.cameras.can_hold_board;
  in.requests.post(session::HoldBoardRequest{board_});
}

void CalibrationPanel::calibrate() {
  try {
    result_ = calibrator_.calibrate();
    message_.clear();
  } catch (const std::exception& error) {
    message_ = error.what();
  }
}

void CalibrationPanel::draw(const PanelInput& in) {
  const vision::CalibrationBoard& board = calibrator_.board();
  ImGui::Text("board: chessboard %dx%d inner corners, %.0f mm squares", board.inner_corners.width,
              board.inner_corners.height, board.square_m * 1000);
  if (in.record.cameras.can_hold_board) {
    if (ImGui::Checkbox("hold the simulated board up", &board_))
      in.requests.post(session::HoldBoardRequest{board_});
  }
  const cv::Mat& image = in.record.tracking.left_image;
  if (button("Capture view", image.empty() ? "no camera image yet" : "")) captureView(in);
  ImGui::SameLine();
  ImGui::Text("%zu views; coverage %.0f%%", calibrator_.viewCount(),
              100.0 * calibrator_.coverageFraction());
  if (!last_view_.empty()) ImGui::Text("last view: %s", last_view_.c_str());
  if (button("Calibrate", calibrator_.viewCount() < 3 ? "capture at least 3 views first" : ""))
    calibrate();
  results();
  liveImage(image);
  reference(in);
}

void CalibrationPanel::results() {
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
}

void CalibrationPanel::liveImage(const cv::Mat& image) {
  // The live image with what the detector finds in it, or its undistorted preview.
  const vision::CalibrationBoard& board = calibrator_.board();
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
}

void CalibrationPanel::reference(const PanelInput& in) {
  if (!reference_read_) {
    // Where the reference is now: the tracker's, else the session file's.
    const auto& world = in.record.tracking.world;
    reference_id_ = world ? world->reference().id : in.settings.world.reference_id;
    const cv::Vec3d p =
        world ? world->reference().T_robot_ref.translation : in.settings.world.reference_position;
    for (int i = 0; i < 3; ++i) reference_position_[i] = static_cast<float>(p[i]);
    reference_read_ = true;
  }
  heading("reference marker (robot frame)");
  ImGui::TextUnformatted("marker id");
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::InputInt("##id", &reference_id_);
  ImGui::TextUnformatted("position in the robot frame (m)");
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::InputFloat3("##position", reference_position_, "%.3f");
  if (button("Apply reference")) {
    in.requests.post(session::ReferenceRequest{
        reference_id_,
        cv::Vec3d(reference_position_[0], reference_position_[1], reference_position_[2])});
  }
}

// Six views of the simulated board, four frames apart, then calibrated.
void rehearseCalibration(Panel& panel, const ShotSteps& steps) {
  auto& p = static_cast<CalibrationPanel&>(panel);
  p.holdBoard(steps.input(), true);
  for (int view = 0; view < 6; ++view) {
    steps.step(4);
    p.captureView(steps.input());
  }
  p.calibrate();
  steps.step(4);
}

}  // namespace

PanelRegistry::Entry calibrationPanel() {
  PanelParts parts{[] { return std::make_unique<CalibrationPanel>(); }, false};
  parts.shots.push_back({"calibration", "six views of the simulated board, calibrated",
                         [](const session::CycleRecord& r) { return r.frame >= 1; },
                         rehearseCalibration});
  return {"calibration", "camera calibration from chessboard views, and the reference marker",
          std::move(parts)};
}

}  // namespace arbci::ui
