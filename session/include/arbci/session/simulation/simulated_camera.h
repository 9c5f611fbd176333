// A simulated camera: draws the Scene from a camera pose with the camera's calibrated intrinsics
// (anti-aliased, on the CPU: no GL context), then adds what real cameras add when asked: lens
// distortion (the camera model's), blur, sensor noise and uneven lighting. Its frames go through
// the real tracker.
#pragma once

#include <cstdint>
#include <memory>

#include <opencv2/core.hpp>

#include "arbci/session/simulation/scene.h"
#include "arbci/vision/camera_model.h"

namespace arbci::session {

class ScenePainter;

struct CameraEffects {
  bool distort = false;      // apply the camera model's distortion
  double blur_sigma = 0.0;   // pixels
  double noise_sigma = 0.0;  // grey levels
  double vignetting = 0.0;   // brightness lost at the corners (0-1)
  double gradient = 0.0;     // brightness lost from left to right (0-1)
};

class SimulatedCamera {
 public:
  // `camera` gives the image size and intrinsics; `seed` the noise.
  explicit SimulatedCamera(const vision::CameraModel& camera, std::uint64_t seed = 1);
  ~SimulatedCamera();
  SimulatedCamera(const SimulatedCamera&) = delete;
  SimulatedCamera& operator=(const SimulatedCamera&) = delete;

  // A BGR frame of `scene` seen from `T_cam_world` (x right, y down, z forward in the camera).
  cv::Mat render(const Scene& scene, const vision::Pose& T_cam_world,
                 const CameraEffects& effects = {});
  const vision::CameraModel& camera() const { return camera_; }

 private:
  vision::CameraModel camera_;
  std::unique_ptr<ScenePainter> painter_;
  cv::Mat distort_map1_, distort_map2_;  // fixed-point remap tables of the lens
  cv::Mat gain_;  // uneven light (CV_16SC3, 256 = 1), for the last effects used
  double gain_vignetting_ = -1.0, gain_gradient_ = -1.0;
  cv::Mat noise_;  // a noise field larger than the frame (CV_16SC3)
  double noise_sigma_ = -1.0;
  cv::RNG random_;
};

}  // namespace arbci::session
