// The cameras' stage: each cycle, this frame's images from the scene (the simulated world, or
// camera devices and video files), which the tracking stage takes next. The scene is shown the
// robot's latest report of its world (a simulated scene moves its objects and gripper there).
#pragma once

#include <memory>

#include "session/robot_choreography.h"
#include "session/scene_source.h"
#include "session/stage.h"

namespace arbci::app {

class CameraStage final : public Stage {
 public:
  CameraStage(std::unique_ptr<SceneSource> scene, const RobotChoreography& robot)
      : scene_(std::move(scene)), robot_(robot) {}

  const char* name() const override { return "cameras"; }
  void step(CycleContext& cycle) override {
    frames_ = scene_->capture(cycle.frame, cycle.time_s, robot_.status());
  }

  // What this cycle captured (empty images: nothing new).
  const SceneSource::Frames& frames() const { return frames_; }
  SceneSource& scene() { return *scene_; }
  const SceneSource& scene() const { return *scene_; }

 private:
  std::unique_ptr<SceneSource> scene_;
  const RobotChoreography& robot_;
  SceneSource::Frames frames_;
};

}  // namespace arbci::app
