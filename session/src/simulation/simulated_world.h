// The embedded default world: a table with the session's objects, the reference marker, and a
// stereo camera rig at the subject's head with slight head motion. The objects stand where the
// simulated robot's world says (its STATUS), so where the robot puts an object, the cameras see
// it there. The cameras' frames go through the real tracker.
#pragma once

#include <memory>
#include <optional>

#include "arbci/robot/protocol.h"
#include "arbci/robot/robot_config.h"
#include "arbci/session/scene_source.h"
#include "arbci/session/simulation/scene.h"
#include "arbci/session/simulation/simulated_camera.h"

namespace arbci::session {

class SimulatedWorld {
 public:
  explicit SimulatedWorld(const SceneSettings& settings);
  ~SimulatedWorld();

  // The arbci-robotd configuration for this world (objects, table, workspace).
  robot::RobotConfig robotConfig() const;
  // Moves objects and the gripper to where the robot reports them.
  void update(const robot::StatusPayload& status);
  // The cameras' true poses at time `t` (seconds): T_cam_world of the left and the right camera.
  vision::Pose leftCamera(double t) const;
  vision::Pose rightCamera(double t) const;
  // The right camera's pose in the left's frame (the rig's extrinsics).
  vision::Pose T_right_left() const;
  const vision::CameraModel& camera() const { return camera_; }
  struct Frame {
    cv::Mat image;
    bool changed = true;  // false: nothing in view moved since this camera's last frame (the same)
  };
  // One camera's frame at time `t` (the cycle renders the two on alternate frames, so no cycle
  // pays for both). A frame is rendered again only when the head, an object, the gripper or a
  // hand over a marker moved.
  Frame captureLeft(double t);
  Frame captureRight(double t);
  const Scene& scene() const { return scene_; }
  // Holds a 9x6 chessboard (25 mm squares) up in front of the left camera, each call at the next
  // of a dozen poses (tilted, near and far, off centre), or puts it away.
  void holdBoard(bool show, double t);
  // The true top-centre position of object `id` (robot frame), if it exists.
  std::optional<cv::Vec3d> objectPosition(int id) const;

 private:
  SceneSettings settings_;
  vision::CameraModel camera_;
  Scene scene_;
  std::unique_ptr<SimulatedCamera> left_, right_;
  double approach_height_ = 0.0;  // the simulated arm's, above a grasp's target
  struct Cache {
    std::uint64_t scene_revision = 0;
    std::optional<vision::Pose> pose;
    cv::Mat image;
  };
  Frame capture(SimulatedCamera& camera, Cache& cache, const vision::Pose& pose);
  // The hands over markers at time `t` (world.objects[].covered_s).
  void coverAt(double t);
  std::uint64_t scene_revision_ = 1;
  int board_pose_ = 0;
  Cache left_cache_, right_cache_;
};

}  // namespace arbci::session
