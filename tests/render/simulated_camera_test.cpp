// The simulated camera's frames go through the real tracker: a marker rendered at a known pose
// is found with its ID and a pose within 1 cm and 1 degree, through a distorting lens too.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>

#include "arbci/render/camera_projection.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/simulated_camera.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/undistortion.h"
#include "render/test_camera.h"

namespace arbci::render {
namespace {

Scene oneObject(int id, const vision::Pose& top) {
  Scene scene;
  SceneObject object;
  object.marker = {vision::MarkerKind::Bch, id, 0.05, 0.125};
  object.T_world_top = top;
  scene.objects.push_back(object);
  return scene;
}

void expectDetectedAt(const cv::Mat& frame, const vision::CameraModel& camera, bool distorted,
                      int id, const vision::Pose& truth) {
  vision::DetectorConfig config;
  if (distorted)
    config.lens = std::make_shared<vision::Undistorter>(camera, vision::UndistortMode::LookupTable);
  vision::MarkerDetector detector(config);
  const auto markers = detector.detect(frame).markers;
  const vision::MarkerDetection* found = nullptr;
  for (const auto& m : markers) {
    if (m.id == id) found = &m;
  }
  ASSERT_NE(found, nullptr) << markers.size() << " markers, none with id " << id;
  std::vector<cv::Point2d> image;
  for (const auto& p : found->ideal_corners) image.emplace_back(p.x, p.y);
  const auto object = vision::markerCorners(0.05);
  const vision::PoseEstimate estimate = vision::estimatePose(object, image, camera.camera_matrix);
  EXPECT_LT(cv::norm(estimate.pose.translation - truth.translation), 0.01);
  EXPECT_LT(vision::rotationAngleDeg(estimate.pose.rotation, truth.rotation), 1.0);
}

TEST(SimulatedCamera, AMarkerAtAKnownPoseIsTrackedWithinACentimetreAndADegree) {
  auto context = createHeadlessContext({64, 64});
  const vision::CameraModel camera = test::camera640();
  SimulatedCamera simulated(camera);
  const vision::Pose T_cam_world = vision::cameraLookingAt({0.05, 1.45, 0.45}, {0.0, 0.65, 0.0});
  for (const auto& [x, y, spin] : std::vector<std::tuple<double, double, double>>{
           {0.0, 0.6, 0.0}, {0.15, 0.5, 30.0}, {-0.2, 0.75, -60.0}}) {
    const double a = spin * M_PI / 180.0;
    const vision::Pose top{
        cv::Matx33d(std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1),
        cv::Vec3d(x, y, 0.06)};
    const cv::Mat frame = simulated.render(oneObject(12, top), T_cam_world);
    ASSERT_EQ(frame.size(), cv::Size(640, 480));
    expectDetectedAt(frame, camera, false, 12, T_cam_world * top);
  }
}

TEST(SimulatedCamera, ThroughADistortingLensWithNoiseAndBlur) {
  auto context = createHeadlessContext({64, 64});
  vision::CameraModel camera = test::camera640();
  camera.distortion = {-0.20, 0.05, 0.0, 0.0, 0.0};
  SimulatedCamera simulated(camera, 7);
  const vision::Pose T_cam_world = vision::cameraLookingAt({-0.05, 1.4, 0.5}, {0.0, 0.6, 0.0});
  const vision::Pose top{cv::Matx33d::eye(), cv::Vec3d(0.2, 0.55, 0.06)};
  CameraEffects effects;
  effects.distort = true;
  effects.noise_sigma = 4.0;
  effects.blur_sigma = 0.7;
  effects.vignetting = 0.3;
  const cv::Mat frame = simulated.render(oneObject(100, top), T_cam_world, effects);
  expectDetectedAt(frame, camera, true, 100, T_cam_world * top);
  // The reference marker (id 0, 8 cm) on the table is seen as well.
  vision::DetectorConfig config;
  config.lens = std::make_shared<vision::Undistorter>(camera, vision::UndistortMode::LookupTable);
  vision::MarkerDetector detector(config);
  bool reference = false;
  for (const auto& m : detector.detect(frame).markers) reference |= m.id == 0;
  EXPECT_TRUE(reference);
}

}  // namespace
}  // namespace arbci::render
