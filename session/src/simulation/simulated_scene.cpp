#include "simulation/simulated_scene.h"

#include <algorithm>
#include <cmath>

#include "simulation/simulated_world.h"

namespace arbci::session {
namespace {

// The simulated world's cameras, rendered on alternate display frames (no cycle pays for both).
class SimulatedScene final : public SceneSource {
 public:
  explicit SimulatedScene(const SceneSettings& settings)
      : world_(settings),
        camera_every_(std::max(
            1, static_cast<int>(std::lround(settings.display_hz / settings.cameras.rate_hz)))) {
    left_camera_ = right_camera_ = world_.camera();
    T_right_left_ = world_.T_right_left();
  }
  Frames capture(std::int64_t frame, double time_s,
                 const std::optional<robot::StatusPayload>& robot) override {
    Frames frames;
    // The right camera half a camera period later (at 60 Hz, both every frame).
    const bool left_due = frame % camera_every_ == 0;
    const bool right_due = camera_every_ == 1 || frame % camera_every_ == 1;
    if (left_due) {
      // The objects and the gripper where the robot last reported them (the right camera, half
      // a camera period later, sees the same scene).
      if (robot) world_.update(*robot);
      const SimulatedWorld::Frame left = world_.captureLeft(time_s);
      frames.left = left.image;
      frames.left_changed = left.changed;
    }
    if (right_due) frames.right = world_.captureRight(time_s).image;
    return frames;
  }
  std::vector<std::pair<cv::Mat, cv::Mat>> warmUpFrames() override {
    std::vector<std::pair<cv::Mat, cv::Mat>> frames;
    for (int i = 0; i < 3; ++i)
      frames.emplace_back(world_.captureLeft(-1.0 - i).image, world_.captureRight(-1.0 - i).image);
    return frames;
  }
  robot::RobotConfig simulatedRobot() const override { return world_.robotConfig(); }
  bool canHoldBoard() const override { return true; }
  void holdBoard(bool show, double time_s) override { world_.holdBoard(show, time_s); }

 private:
  SimulatedWorld world_;
  int camera_every_;
};

}  // namespace

std::unique_ptr<SceneSource> makeSimulatedScene(const SceneSettings& settings) {
  return std::make_unique<SimulatedScene>(settings);
}

}  // namespace arbci::session
