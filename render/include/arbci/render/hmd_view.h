// The subject's view in the video see-through HMD: side by side, one viewport per eye, each with
// its camera's image as background and the virtual content projected with that camera's
// calibrated intrinsics. Optionally the background is undistorted on the GPU through the
// calibration's map, scaled so the rectified image fills the view without empty borders, and the
// virtual camera is matched to that rectified view.
#pragma once

#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core/mat.hpp>

#include "arbci/render/gl_context.h"
#include "arbci/vision/camera_model.h"
#include "arbci/vision/pose.h"

namespace arbci::render {

// Lost: the pose is older than the session allows (greyed, dashed in spirit: never flashed).
enum class HighlightState { Idle, Cued, Flashing, Selected, Held, Lost };

struct ObjectHighlight {
  int id = 0;
  vision::Pose T_world_top;  // the marker's frame on the object's top, robot frame
  double side_m = 0.05;      // outline: the marker's black square, enlarged by `margin`
  double margin = 1.3;
  HighlightState state = HighlightState::Idle;
};

// A rows x columns grid of square cells on the table, centred on its frame's origin; row 1 is the
// far row (+y of the grid frame), column 1 the left one (-x).
struct GridLayout {
  vision::Pose T_world_grid;
  int rows = 0, columns = 0;  // the session's world.grid
  double cell_m = 0.0;
  // The centre of cell (row, column), 1-based, in the world frame.
  cv::Vec3d cellCentre(int row, int column) const;
  cv::Vec3d cellCorner(double row_edge, double column_edge) const;  // edges 0..rows, 0..columns
};

struct GridHighlight {
  std::set<int> rows, columns;                        // flashing rows and columns (1-based)
  std::optional<std::pair<int, int>> cued, selected;  // (row, column)
};

struct EyeImage {
  cv::Mat image;  // the camera frame (BGR or grey); empty: black
  vision::CameraModel camera;
  std::optional<vision::Pose> T_cam_world;  // unknown until the reference marker is seen
};

struct HmdFrame {
  EyeImage left, right;
  std::vector<ObjectHighlight> objects;
  std::optional<GridLayout> grid;
  GridHighlight grid_highlight;
  // The photodiode patch in the top-left corner of each eye: white on frames that show a flash,
  // black on the others, so a diode taped there sees exactly what the subject saw. nullopt: none.
  std::optional<bool> photodiode_patch;
  static constexpr int kPatchPx = 32;  // its side in pixels of the eye's viewport
};

struct HmdColors {
  glm::vec4 idle{1.0f, 1.0f, 1.0f, 0.9f};
  glm::vec4 cued{0.2f, 0.9f, 1.0f, 1.0f};
  glm::vec4 flash{1.0f, 1.0f, 0.3f, 0.85f};  // filled
  glm::vec4 selected{0.2f, 1.0f, 0.3f, 1.0f};
  glm::vec4 held{0.3f, 0.5f, 1.0f, 1.0f};
  glm::vec4 grid{0.9f, 0.9f, 0.9f, 0.8f};
  glm::vec4 lost{0.45f, 0.45f, 0.45f, 0.6f};
};

class HmdView {
 public:
  HmdView();  // needs a current GL context
  ~HmdView();
  HmdView(const HmdView&) = delete;
  HmdView& operator=(const HmdView&) = delete;

  void setUndistort(bool undistort) { undistort_ = undistort; }
  bool undistort() const { return undistort_; }
  HmdColors& colors() { return colors_; }

  // Draws both eyes side by side into `framebuffer` (the left half for the left eye).
  void draw(const HmdFrame& frame, unsigned int framebuffer, Size size);

  // Where a world point appears in an eye's viewport (viewport pixels, OpenCV convention), as
  // drawn: through the rectified camera when undistorting, through the lens model otherwise.
  std::optional<cv::Point2d> project(const EyeImage& eye, const cv::Vec3d& world,
                                     Size viewport) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool undistort_ = false;
  HmdColors colors_;
};

}  // namespace arbci::render
