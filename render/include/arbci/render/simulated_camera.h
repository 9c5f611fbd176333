// A simulated camera: renders the Scene from a camera pose with the camera's calibrated
// intrinsics (anti-aliased), then adds what real cameras add when asked: lens distortion (the
// camera model's), blur, sensor noise and uneven lighting. Its frames go through the real tracker.
#pragma once

#include <cstdint>
#include <memory>
#include <random>

#include <opencv2/core/mat.hpp>

#include "arbci/render/scene.h"
#include "arbci/render/scene_renderer.h"
#include "arbci/vision/camera_model.h"

namespace arbci::render {

struct CameraEffects {
  bool distort = false;       // apply the camera model's distortion
  double blur_sigma = 0.0;    // pixels
  double noise_sigma = 0.0;   // grey levels
  double vignetting = 0.0;    // brightness lost at the corners (0-1)
  double gradient = 0.0;      // brightness lost from left to right (0-1)
};

class SimulatedCamera {
 public:
  // Needs a current GL context; `camera` gives the image size and intrinsics.
  SimulatedCamera(const vision::CameraModel& camera, std::uint64_t seed = 1);
  ~SimulatedCamera();
  SimulatedCamera(const SimulatedCamera&) = delete;
  SimulatedCamera& operator=(const SimulatedCamera&) = delete;

  // A BGR frame of `scene` seen from `T_cam_world` (x right, y down, z forward in the camera).
  cv::Mat render(const Scene& scene, const vision::Pose& T_cam_world, const CameraEffects& effects = {});
  const vision::CameraModel& camera() const { return camera_; }

 private:
  vision::CameraModel camera_;
  SceneRenderer renderer_;
  unsigned int multisample_fbo_ = 0, color_rb_ = 0, depth_rb_ = 0, resolve_fbo_ = 0, resolve_rb_ = 0;
  cv::Mat distort_x_, distort_y_;
  std::mt19937_64 random_;
};

}  // namespace arbci::render
