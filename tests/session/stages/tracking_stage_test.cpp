// The tracking stage on hand-built records: camera frames drawn with markers at known poses give
// the robot-frame world through the reference marker; what the robot moved is forgotten until seen
// again; an unchanged frame keeps the poses fresh without tracking; the experimenter's threshold
// and reference apply from the next frame and are on the record.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "arbci/session/session_config.h"
#include "arbci/session/stages/tracking_stage.h"
#include "support/posed_markers.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

vision::CameraModel pinhole() {
  vision::CameraModel c;
  c.camera_matrix = cv::Matx33d(900, 0, 639.5, 0, 900, 359.5, 0, 0, 1);
  c.image_size = {1280, 720};
  return c;
}

TrackingSettings settings() {
  const SessionConfig defaults;
  TrackingSettings t{defaults.tracker.detector,
                     0,
                     0.08,
                     {0.0, 0.9, 0.0},
                     {{20, 0.05}, {40, 0.05}},
                     0.5,
                     pinhole(),
                     pinhole(),
                     {},
                     {}};
  return t;
}

// Where the objects lie on the table (robot frame).
const std::map<int, cv::Vec3d> kObjects{{20, {0.12, 0.72, 0.0}}, {40, {-0.10, 0.66, 0.0}}};

// The table seen from the subject's head: the reference marker at (0, 0.90, 0) and the objects
// `ids` where kObjects has them.
cv::Mat frameWith(const std::vector<int>& ids) {
  const vision::Pose T_cam_robot =
      vision::cameraLookingAt(cv::Vec3d(0.0, 1.30, 0.45), cv::Vec3d(0.0, 0.74, 0.0));
  cv::Mat frame(720, 1280, CV_8UC1, cv::Scalar(150));
  test::drawPosedMarker(frame, pinhole().camera_matrix,
                        T_cam_robot * vision::Pose{cv::Matx33d::eye(), {0.0, 0.9, 0.0}}, 0.08,
                        test::MarkerFamily::ArbciBch, 0);
  for (int id : ids) {
    test::drawPosedMarker(frame, pinhole().camera_matrix,
                          T_cam_robot * vision::Pose{cv::Matx33d::eye(), kObjects.at(id)}, 0.05,
                          test::MarkerFamily::ArbciBch, id);
  }
  cv::Mat bgr;  // as the cameras deliver it
  cv::cvtColor(frame, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

TEST(TrackingStage, MarkersInAFrameGiveTheRobotFrameWorldThroughTheReference) {
  test::StageBench bench("tracking");
  TrackingStage stage(settings(), bench.services());
  bench.record.cameras.left = frameWith({20, 40});
  bench.step(stage);
  const TrackingPart& t = bench.record.tracking;
  ASSERT_NE(t.world, nullptr);
  EXPECT_TRUE(t.fresh(20, bench.record.time_s));
  const auto object = t.world->object(20);
  ASSERT_TRUE(object.has_value());
  EXPECT_LT(cv::norm(object->T_robot_object.translation - kObjects.at(20)), 0.005);
  EXPECT_EQ(t.detection.markers.size(), 3u);
  EXPECT_FALSE(t.binary.empty());
  EXPECT_EQ(t.left_image.data, bench.record.cameras.left.data);
  ASSERT_TRUE(t.T_cam_world_left.has_value());
  EXPECT_EQ(t.alarm({20, 40}, bench.record.time_s), "");
}

TEST(TrackingStage, AnObjectTheRobotMovedIsUnknownUntilAFrameShowsItAgain) {
  test::StageBench bench("tracking_moved");
  TrackingStage stage(settings(), bench.services());
  const cv::Mat both = frameWith({20, 40});
  bench.record.cameras.left = both;
  bench.step(stage);
  bench.next();
  bench.record.robot.moved = {20};
  bench.step(stage);
  EXPECT_FALSE(bench.record.tracking.world->object(20).has_value());
  EXPECT_TRUE(bench.record.tracking.world->object(40).has_value());
  EXPECT_NE(bench.record.tracking.alarm({20, 40}, bench.record.time_s).find("object 20"),
            std::string::npos);
  bench.next();
  bench.record.cameras.left = both;
  bench.step(stage);
  EXPECT_TRUE(bench.record.tracking.fresh(20, bench.record.time_s));
}

TEST(TrackingStage, AnUnchangedFrameKeepsThePosesFreshAndNoFrameLetsThemAge) {
  test::StageBench bench("tracking_unchanged");
  TrackingStage stage(settings(), bench.services());
  bench.record.cameras.left = frameWith({20});
  bench.step(stage);
  for (int i = 0; i < 60; ++i) {
    bench.next();
    bench.record.cameras.left = bench.previous.tracking.left_image;
    bench.record.cameras.left_changed = false;
    bench.step(stage);
  }
  EXPECT_TRUE(bench.record.tracking.fresh(20, bench.record.time_s));
  // No frame for a second: older than the allowed half second.
  for (int i = 0; i < 60; ++i) {
    bench.next();
    bench.step(stage);
  }
  EXPECT_FALSE(bench.record.tracking.fresh(20, bench.record.time_s));
  EXPECT_NE(bench.record.tracking.alarm({20}, bench.record.time_s).find("tracking lost"),
            std::string::npos);
}

TEST(TrackingStage, TheExperimentersThresholdAndReferenceApplyAndAreOnTheRecord) {
  test::StageBench bench("tracking_requests");
  TrackingStage stage(settings(), bench.services());
  vision::ThresholdSettings constant;
  constant.mode = vision::ThresholdMode::Constant;
  constant.value = 90;
  // The reference marker said to lie elsewhere in the robot's frame.
  bench.record.requests = {ThresholdRequest{constant}, ReferenceRequest{0, {0.3, 0.7, 0.0}}};
  bench.record.cameras.left = frameWith({20, 40});
  bench.step(stage);
  const TrackingPart& t = bench.record.tracking;
  EXPECT_EQ(t.threshold.mode, vision::ThresholdMode::Constant);
  EXPECT_EQ(t.threshold.value, 90);
  EXPECT_EQ(t.detection.threshold, 90);
  EXPECT_NEAR(t.world->reference().T_robot_ref.translation[0], 0.3, 1e-12);
  // Object 20 lies where it lies relative to the reference, now at (0.3, 0.7, 0).
  const auto object = t.world->object(20);
  ASSERT_TRUE(object.has_value());
  const cv::Vec3d expected = cv::Vec3d(0.3, 0.7, 0.0) + kObjects.at(20) - cv::Vec3d(0.0, 0.9, 0.0);
  EXPECT_LT(cv::norm(object->T_robot_object.translation - expected), 0.005);
  EXPECT_EQ(bench.logged("reference").size(), 1u);
}

}  // namespace
}  // namespace arbci::session
