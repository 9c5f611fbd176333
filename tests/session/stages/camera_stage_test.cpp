// The cameras' stage on hand-built records, over a scene of the test's own: this frame's images
// published for tracking, the robot's last report shown to the scene, the experimenter's board
// request passed on.
#include <gtest/gtest.h>

#include "arbci/session/stages/camera_stage.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

// A new left frame every other display frame, grey at the frame number; it remembers what it was
// shown and asked.
class CountingScene final : public SceneSource {
 public:
  Frames capture(std::int64_t frame, double,
                 const std::optional<robot::StatusPayload>& robot) override {
    robots.push_back(robot.has_value() ? robot->holding : -2);
    Frames frames;
    if (frame % 2 == 0) frames.left = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(double(frame)));
    frames.right = cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(1.0));
    return frames;
  }
  bool canHoldBoard() const override { return true; }
  void holdBoard(bool show, double) override { boards.push_back(show); }
  std::vector<int> robots;  // the robot's report each capture saw: what it held (-2: none)
  std::vector<bool> boards;
};

TEST(CameraStage, ThisFramesImagesArePublishedAndTheSceneSeesTheRobotsLastReport) {
  test::StageBench bench("cameras");
  auto own = std::make_unique<CountingScene>();
  CountingScene& scene = *own;
  CameraStage stage(std::move(own));
  bench.step(stage);
  EXPECT_TRUE(bench.record.cameras.any());
  EXPECT_EQ(bench.record.cameras.left.at<cv::Vec3b>(0, 0)[0], 0);
  EXPECT_TRUE(bench.record.cameras.can_hold_board);
  bench.next();
  // The robot stage runs after the cameras: they show last cycle's report of the arm's world.
  robot::StatusPayload status;
  status.holding = 40;
  bench.previous.robot.status = status;
  bench.step(stage);
  EXPECT_TRUE(bench.record.cameras.left.empty());
  EXPECT_FALSE(bench.record.cameras.right.empty());
  EXPECT_EQ(scene.robots, (std::vector<int>{-2, 40}));
}

TEST(CameraStage, TheExperimentersBoardRequestsReachTheSceneInOrder) {
  test::StageBench bench("cameras_board");
  auto own = std::make_unique<CountingScene>();
  CountingScene& scene = *own;
  CameraStage stage(std::move(own));
  bench.record.requests = {HoldBoardRequest{true}, ThresholdRequest{}, HoldBoardRequest{false}};
  bench.step(stage);
  EXPECT_EQ(scene.boards, (std::vector<bool>{true, false}));
}

}  // namespace
}  // namespace arbci::session
