// The robot frame through the reference marker: objects on the table, seen by a head-mounted
// camera, come out at their robot-frame positions; the reference's absence is said plainly.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/world_model.h"
#include "support/posed_markers.h"

namespace arbci::vision {
namespace {

TEST(RobotFrame, ObjectsOnTheTableComeOutWithin5MillimetresThroughTheReferenceMarker) {
  const cv::Matx33d k(900, 0, 639.5, 0, 900, 359.5, 0, 0, 1);
  ReferenceMarker reference;  // id 0 at (0, 0.90, 0)
  reference.size_m = 0.08;
  WorldModel world(reference);
  const std::map<int, cv::Vec3d> objects{
      {5, {0.12, 0.72, 0.0}}, {6, {-0.10, 0.66, 0.0}}, {7, {0.02, 0.80, 0.0}}};
  // Slight head motion over a few frames.
  for (int frame_index = 0; frame_index < 4; ++frame_index) {
    const Pose T_robot_cam =
        cameraLookingAt(cv::Vec3d(0.01 * frame_index, 1.30, 0.45), cv::Vec3d(0.0, 0.74, 0.0))
            .inverse();
    const Pose T_cam_robot = T_robot_cam.inverse();
    cv::Mat frame(720, 1280, CV_8UC1, cv::Scalar(150));
    test::drawPosedMarker(frame, k, T_cam_robot * reference.T_robot_ref, reference.size_m,
                          test::MarkerFamily::ArbciBch, 0);
    for (const auto& [id, position] : objects) {
      test::drawPosedMarker(frame, k, T_cam_robot * Pose{cv::Matx33d::eye(), position}, 0.05,
                            test::MarkerFamily::ArbciBch, id);
    }
    MarkerDetector detector(DetectorConfig{});
    std::map<int, PoseEstimate> poses;
    for (const MarkerDetection& m : detector.detect(frame).markers) {
      const double size = m.id == reference.id ? reference.size_m : 0.05;
      std::vector<cv::Point2d> corners;
      for (const cv::Point2f& p : m.ideal_corners) corners.emplace_back(p.x, p.y);
      poses[m.id] = estimatePose(markerCorners(size), corners, k);
    }
    ASSERT_EQ(poses.size(), 4u);
    const auto updated = world.update(frame_index / 30.0, poses);
    EXPECT_EQ(updated.size(), 3u);
    for (const auto& [id, position] : objects) {
      const auto state = world.object(id);
      ASSERT_TRUE(state.has_value());
      EXPECT_LT(cv::norm(state->T_robot_object.translation - position), 0.005)
          << "object " << id << " at " << state->T_robot_object.translation << ", truth "
          << position;
    }
    EXPECT_TRUE(world.referenceVisible(frame_index / 30.0));
  }
}

TEST(RobotFrame, WithoutTheReferenceObjectsAgeAndTheStatusSaysSo) {
  WorldModel world;
  EXPECT_NE(world.status(0.0).find("not seen yet"), std::string::npos);
  PoseEstimate reference, object;
  reference.pose.translation = {0, 0, 0.5};
  object.pose.translation = {0.1, 0, 0.5};
  world.update(1.0, {{0, reference}, {5, object}});
  EXPECT_TRUE(world.referenceVisible(1.2));
  EXPECT_EQ(world.update(3.0, {{5, object}}).size(), 0u);  // no reference: nothing updated
  EXPECT_FALSE(world.referenceVisible(3.0));
  EXPECT_NEAR(world.object(5)->age(3.0), 2.0, 1e-12);
  EXPECT_NE(world.status(3.0).find("not seen for 2.0 s"), std::string::npos) << world.status(3.0);
}

TEST(RobotFrame, AMovedObjectHasNoPoseUntilSeenAgain) {
  WorldModel world;
  PoseEstimate reference, object;
  reference.pose.translation = {0, 0, 0.5};
  object.pose.translation = {0.1, 0, 0.5};
  world.update(1.0, {{0, reference}, {5, object}});
  ASSERT_TRUE(world.object(5));
  world.forget(5);
  EXPECT_FALSE(world.object(5));
  EXPECT_TRUE(world.objects().empty());
  object.pose.translation = {-0.1, 0, 0.5};
  world.update(2.0, {{0, reference}, {5, object}});
  ASSERT_TRUE(world.object(5));
  EXPECT_NEAR(world.object(5)->T_robot_object.translation[0],
              world.T_robot_cam()->apply(object.pose.translation)[0], 1e-12);
}

}  // namespace
}  // namespace arbci::vision
