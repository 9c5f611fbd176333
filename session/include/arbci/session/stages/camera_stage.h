// The cameras' stage: each cycle, this frame's images from the scene (the simulated world, or
// camera devices and video files), which tracking takes next. The scene is shown the robot's
// latest report of its world (a simulated scene moves its objects and gripper there).
#pragma once

#include <memory>

#include "arbci/session/scene_source.h"
#include "arbci/session/stage.h"

namespace arbci::session {

class CameraStage final : public Stage {
 public:
  explicit CameraStage(std::unique_ptr<SceneSource> scene) : scene_(std::move(scene)) {}
  const char* name() const override { return "cameras"; }
  void step(Cycle& cycle) override {
    for (const auto* hold : requestsOf<HoldBoardRequest>(cycle.record.requests))
      scene_->holdBoard(hold->show, cycle.time_s);
    const SceneSource::Frames frames =
        scene_->capture(cycle.frame, cycle.time_s, cycle.previous.robot.status);
    CameraPart& out = cycle.record.cameras;
    out.left = frames.left;
    out.left_changed = frames.left_changed;
    out.right = frames.right;
    out.can_hold_board = scene_->canHoldBoard();
  }

 private:
  std::unique_ptr<SceneSource> scene_;
};

}  // namespace arbci::session
