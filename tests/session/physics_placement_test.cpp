// The physics driver's world as the cameras see it: an object the mujoco arm lets go 0.2 m above
// the table falls and rests where physics puts it; drawn at the pose the driver reports (as the
// simulated world draws it), the tracker finds its marker within 5 mm of that pose.
#include <gtest/gtest.h>

#include "arbci/robot/mujoco_arm.h"
#include "arbci/session/simulation/simulated_camera.h"
#include "arbci/vision/marker_detector.h"
#include "support/test_camera.h"

namespace arbci::session {
namespace {

robot::DriverResult runToEnd(robot::MujocoArm& arm, const robot::DriverCommand& command) {
  EXPECT_FALSE(arm.check(command));
  arm.start(command);
  for (int i = 0; i < 2000; ++i) {
    if (auto result = arm.step(0.05)) return *result;
  }
  return {robot::Outcome::Failed, "did not end"};
}

TEST(PhysicsPlacement, AnObjectDroppedFromTwentyCentimetresIsSeenWhereTheArmReportsIt) {
  robot::RobotConfig config;
  config.objects = {{20, {-0.09, 0.42, 0.06}, 0.06, 0.035}};
  robot::MujocoArm arm(config);
  ASSERT_EQ(runToEnd(arm, {robot::MessageType::Grasp, {-0.09, 0.42, 0.06}}).outcome,
            robot::Outcome::Success);
  ASSERT_EQ(runToEnd(arm, {robot::MessageType::Drop, {0.05, 0.62, 0.2}}).outcome,
            robot::Outcome::Success);
  ASSERT_EQ(runToEnd(arm, {robot::MessageType::Home, {}}).outcome, robot::Outcome::Success);
  const robot::WorldObject reported = arm.world().front();
  const vision::Pose top{vision::rotationFromQuaternion(reported.orientation),
                         {reported.position.x, reported.position.y, reported.position.z}};
  // Resting on the table: its top face at its height (upright) or at half its width (on a side).
  const double top_z = reported.position.z;
  EXPECT_TRUE(std::abs(top_z - 0.06) < 0.002 || std::abs(top_z - 0.035) < 0.002) << top_z;

  Scene scene;
  SceneObject object;
  object.marker = {vision::MarkerKind::Bch, 20, 0.05, 0.125};
  object.width_m = 0.07;
  object.height_m = 0.06;
  object.T_world_top = top;
  scene.objects.push_back(object);
  const vision::CameraModel camera = test::camera640();
  SimulatedCamera simulated(camera);
  // The default session's head, looking at the table.
  const vision::Pose T_cam_world = vision::cameraLookingAt({0.0, 1.2, 0.75}, {0.0, 0.7, 0.0});
  const cv::Mat frame = simulated.render(scene, T_cam_world);
  vision::MarkerDetector detector{vision::DetectorConfig{}};
  const vision::MarkerDetection* found = nullptr;
  const auto markers = detector.detect(frame).markers;
  for (const auto& m : markers) {
    if (m.id == 20) found = &m;
  }
  ASSERT_NE(found, nullptr) << "the marker is not in view (on a side facing away?)";
  std::vector<cv::Point2d> corners;
  for (const auto& p : found->ideal_corners) corners.emplace_back(p.x, p.y);
  const vision::PoseEstimate seen =
      vision::estimatePose(vision::markerCorners(0.05), corners, camera.camera_matrix);
  const vision::Pose T_world_top_seen = T_cam_world.inverse() * seen.pose;
  EXPECT_LT(cv::norm(T_world_top_seen.translation - top.translation), 0.005)
      << "seen at " << T_world_top_seen.translation << ", reported " << top.translation;
}

}  // namespace
}  // namespace arbci::session
