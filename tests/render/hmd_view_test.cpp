// The HMD view, rendered headless and read back: highlights land on the marker's projected
// corners, grid lines where the reference pose puts them, flashes on their frames only, and the
// undistorted background matches its rectified virtual camera.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/hmd_view.h"
#include "arbci/session/simulation/simulated_camera.h"
#include "arbci/vision/marker_detector.h"
#include "support/test_camera.h"

namespace arbci::render {
namespace {

using session::CameraEffects;
using session::Scene;
using session::SceneObject;
using session::SimulatedCamera;

cv::Mat toMat(const RgbaImage& image) {
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

// The centre line of a stroke of colour channel `channel` crossing segment a-b, as a fitted line.
// Scans `reach` pixels to either side (less than the distance to any other stroke).
cv::Vec4f strokeLine(const cv::Mat& image, int channel, cv::Point2d a, cv::Point2d b,
                     double reach) {
  const cv::Point2d d = (b - a) / cv::norm(b - a), n(-d.y, d.x);
  std::vector<cv::Point2f> centres;
  for (double t = 0.15; t <= 0.85; t += 0.01) {
    const cv::Point2d p = a + (b - a) * t;
    double weight = 0.0, offset = 0.0;
    for (double s = -reach; s <= reach; s += 0.25) {
      const cv::Point2d q = p + n * s;
      const int x = static_cast<int>(std::lround(q.x)), y = static_cast<int>(std::lround(q.y));
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      const double v = image.at<cv::Vec3b>(y, x)[channel];
      weight += v;
      offset += v * s;
    }
    if (weight > 0.0) centres.emplace_back(p + n * (offset / weight));
  }
  cv::Vec4f line;
  cv::fitLine(centres, line, cv::DIST_L2, 0, 0.01, 0.01);
  return line;
}

cv::Point2d intersect(const cv::Vec4f& l1, const cv::Vec4f& l2) {
  const double a1 = l1[0], b1 = -l2[0], c1 = l2[2] - l1[2];
  const double a2 = l1[1], b2 = -l2[1], c2 = l2[3] - l1[3];
  const double t = (c1 * b2 - c2 * b1) / (a1 * b2 - a2 * b1);
  return {l1[2] + t * l1[0], l1[3] + t * l1[1]};
}

struct Rig {
  vision::CameraModel camera = arbci::test::camera640();
  vision::Pose left = vision::cameraLookingAt({-0.032, 1.45, 0.45}, {0.0, 0.65, 0.0});
  vision::Pose right = vision::cameraLookingAt({0.032, 1.45, 0.45}, {0.0, 0.65, 0.0});
};

TEST(HmdView, HighlightCornersLieWithinAPixelOfTheProjectedMarkerCorners) {
  auto context = createHeadlessContext({1280, 480});
  HmdView view;
  view.colors().selected = {1, 0, 0, 1};  // pure red strokes, measurable
  Rig rig;
  HmdFrame frame;
  frame.left = {cv::Mat::zeros(480, 640, CV_8UC3), rig.camera, rig.left};
  frame.right = {cv::Mat::zeros(480, 640, CV_8UC3), rig.camera, rig.right};
  const double a = 0.4;
  ObjectHighlight object;
  object.T_world_top = {
      cv::Matx33d(std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1),
      cv::Vec3d(0.12, 0.55, 0.06)};
  object.side_m = 0.12;  // large on screen, so the strokes of opposite sides lie far apart
  object.margin = 1.0;
  object.state = HighlightState::Selected;
  frame.objects.push_back(object);
  view.draw(frame, context->drawFramebuffer(), {1280, 480});
  const cv::Mat image = toMat(readPixels(context->drawFramebuffer(), {1280, 480}));
  for (int eye = 0; eye < 2; ++eye) {
    const cv::Mat half = image(cv::Rect(eye * 640, 0, 640, 480));
    const EyeImage& e = eye == 0 ? frame.left : frame.right;
    std::vector<cv::Point2d> expected;
    for (const auto& c : vision::markerCorners(0.12)) {
      const cv::Vec3d world = object.T_world_top.apply(cv::Vec3d(c.x, c.y, c.z));
      const cv::Vec3d cam = e.T_cam_world->apply(world);
      expected.emplace_back(700 * cam[0] / cam[2] + 319.5, 700 * cam[1] / cam[2] + 239.5);
    }
    std::vector<cv::Vec4f> lines;
    for (int i = 0; i < 4; ++i)
      lines.push_back(strokeLine(half, 2, expected[i], expected[(i + 1) % 4], 6.0));
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d corner = intersect(lines[(i + 3) % 4], lines[i]);
      EXPECT_LT(cv::norm(corner - expected[i]), 1.0)
          << "eye " << eye << " corner " << i << ": " << corner << " vs " << expected[i];
    }
  }
}

TEST(HmdView, GridLinesLieWhereTheReferencePoseProjectsThem) {
  auto context = createHeadlessContext({1280, 480});
  HmdView view;
  view.colors().grid = {0, 1, 0, 1};
  Rig rig;
  HmdFrame frame;
  frame.left = {cv::Mat::zeros(480, 640, CV_8UC3), rig.camera, rig.left};
  frame.right = {cv::Mat::zeros(480, 640, CV_8UC3), rig.camera, rig.right};
  // The grid 25 cm in front of a reference marker at (0, 0.9, 0), turned by 10 degrees.
  const vision::Pose T_world_ref{cv::Matx33d::eye(), cv::Vec3d(0, 0.9, 0)};
  const double a = 10.0 * M_PI / 180.0;
  const vision::Pose T_ref_grid{
      cv::Matx33d(std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1),
      cv::Vec3d(0.05, -0.30, 0)};
  GridLayout grid;
  grid.T_world_grid = T_world_ref * T_ref_grid;
  grid.rows = 3;
  grid.columns = 4;
  grid.cell_m = 0.07;
  frame.grid = grid;
  view.draw(frame, context->drawFramebuffer(), {1280, 480});
  const cv::Mat image =
      toMat(readPixels(context->drawFramebuffer(), {1280, 480}))(cv::Rect(0, 0, 640, 480));
  auto check = [&](const cv::Vec3d& from, const cv::Vec3d& to) {
    const cv::Point2d a2 = *view.project(frame.left, from, {640, 480}),
                      b2 = *view.project(frame.left, to, {640, 480});
    const cv::Vec4f line = strokeLine(image, 1, a2, b2, 3.0);
    for (double t : {0.3, 0.5, 0.7}) {
      const cv::Point2d p = a2 + (b2 - a2) * t;
      // Distance from the expected point to the drawn line's centre.
      const double distance = std::abs((p.x - line[2]) * line[1] - (p.y - line[3]) * line[0]);
      EXPECT_LT(distance, 1.0) << p;
    }
  };
  for (int r = 0; r <= 3; ++r) check(grid.cellCorner(r, 0), grid.cellCorner(r, 4));
  for (int c = 0; c <= 4; ++c) check(grid.cellCorner(0, c), grid.cellCorner(3, c));
}

TEST(HmdView, AScheduledFlashAppearsOnItsFramesAndNoOther) {
  auto context = createHeadlessContext({1280, 480});
  HmdView view;
  Rig rig;
  HmdFrame frame;
  frame.left = {cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 60, 60)), rig.camera, rig.left};
  frame.right = frame.left;
  frame.right.T_cam_world = rig.right;
  ObjectHighlight object;
  object.T_world_top = {cv::Matx33d::eye(), cv::Vec3d(0.0, 0.6, 0.06)};
  const std::set<int> scheduled{3,  4,  5,  6,
                                14, 15, 16, 17};  // 60 ms flashes at 60 Hz, 120 ms apart
  const cv::Point2d centre = *view.project(frame.left, object.T_world_top.translation, {640, 480});
  for (int f = 0; f < 24; ++f) {
    object.state = scheduled.count(f) ? HighlightState::Flashing : HighlightState::Idle;
    frame.objects = {object};
    view.draw(frame, context->drawFramebuffer(), {1280, 480});
    const RgbaImage image = readPixels(context->drawFramebuffer(), {1280, 480});
    const std::uint8_t* p = image.at(static_cast<int>(centre.x), static_cast<int>(centre.y));
    const bool lit = p[0] > 200 && p[1] > 200 && p[2] < 150;
    EXPECT_EQ(lit, scheduled.count(f) > 0) << "frame " << f;
  }
}

TEST(HmdView, UndistortedBackgroundMatchesItsRectifiedVirtualCamera) {
  auto context = createHeadlessContext({1280, 480});
  vision::CameraModel lens = arbci::test::camera640();
  lens.distortion = {-0.25, 0.08, 0.0, 0.0, 0.0};
  Rig rig;
  SimulatedCamera camera(lens);
  Scene scene;
  SceneObject object;
  object.marker = {vision::MarkerKind::Bch, 42, 0.05, 0.125};
  object.width_m = 0.07;
  object.height_m = 0.06;
  object.T_world_top = {cv::Matx33d::eye(), cv::Vec3d(0.25, 0.5, 0.06)};  // towards the image edge
  scene.objects.push_back(object);
  const cv::Mat distorted = camera.render(scene, rig.left, CameraEffects{true});
  HmdView view;
  view.setUndistort(true);
  HmdFrame frame;
  frame.left = {distorted, lens, rig.left};
  frame.right = frame.left;
  view.draw(frame, context->drawFramebuffer(), {1280, 480});
  const cv::Mat shown =
      toMat(readPixels(context->drawFramebuffer(), {1280, 480}))(cv::Rect(0, 0, 640, 480)).clone();
  // The shown image is an ideal pinhole view: the detector needs no lens model, and the marker's
  // corners sit where the view projects them.
  vision::MarkerDetector detector(vision::DetectorConfig{});
  const vision::MarkerDetection* found = nullptr;
  const auto markers = detector.detect(shown).markers;
  for (const auto& m : markers) {
    if (m.id == 42) found = &m;
  }
  ASSERT_NE(found, nullptr);
  const auto corners = vision::markerCorners(0.05);
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d world =
        object.T_world_top.apply(cv::Vec3d(corners[i].x, corners[i].y, corners[i].z));
    const cv::Point2d expected = *view.project(frame.left, world, {640, 480});
    EXPECT_LT(cv::norm(cv::Point2d(found->corners[i].x, found->corners[i].y) - expected), 1.0) << i;
  }
  // No empty border: the corners of the view show the scene, not black.
  for (const cv::Point corner :
       {cv::Point(1, 1), cv::Point(638, 1), cv::Point(1, 478), cv::Point(638, 478)}) {
    EXPECT_GT(cv::norm(shown.at<cv::Vec3b>(corner)), 30.0) << corner;
  }
}

}  // namespace
}  // namespace arbci::render
