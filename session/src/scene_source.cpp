#include "arbci/session/scene_source.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "arbci/session/camera_capture.h"
#include "simulation/simulated_scene.h"

namespace arbci::session {
namespace {

// Camera devices or video files, each read on its own thread; a new left frame is tracked with
// the right camera's latest.
class DeviceScene final : public SceneSource {
 public:
  explicit DeviceScene(const SceneSettings& settings) {
    const CameraSettings& c = settings.cameras;
    left_camera_ = vision::CameraModel::load(c.left.calibration);
    // Errors name the key: the video file's, or the device's.
    left_ = std::make_unique<CameraCapture>(
        c.left.device, c.left.video,
        c.left.video.empty() ? "cameras.left.device" : "cameras.left.video");
    right_camera_ = left_camera_;
    if (!c.right.calibration.empty()) {
      right_camera_ = vision::CameraModel::load(c.right.calibration);
      right_ = std::make_unique<CameraCapture>(
          c.right.device, c.right.video,
          c.right.video.empty() ? "cameras.right.device" : "cameras.right.video");
      if (!c.stereo_calibration.empty()) {
        const vision::StereoCameras stereo = vision::StereoCameras::load(c.stereo_calibration);
        T_right_left_ = {stereo.rotation, stereo.translation};
      }
    }
  }
  // A black frame of the calibrated size: the tracker builds its lens tables before the cycle.
  std::vector<std::pair<cv::Mat, cv::Mat>> warmUpFrames() override {
    return {{cv::Mat::zeros(left_camera_.image_size, CV_8UC3), cv::Mat()}};
  }
  Frames capture(std::int64_t, double, const std::optional<robot::StatusPayload>&) override {
    Frames frames;
    const auto [left, count] = left_->latest();
    if (count != left_seen_ && !left.empty()) {
      left_seen_ = count;
      frames.left = left;
      if (right_) frames.right = right_->latest().first;
    }
    return frames;
  }

 private:
  std::unique_ptr<CameraCapture> left_, right_;
  std::uint64_t left_seen_ = 0;
};

}  // namespace

SceneSettings SceneSettings::of(const SessionConfig& config) {
  return {config.cameras,
          config.world,
          config.tracker.detector.kind,
          config.tracker.detector.border,
          config.eeg.seed,
          config.paradigm.display_hz,
          config.robot.speed_factor,
          config.source};
}

void SceneSettings::validate() const {
  auto exists = [&](const std::string& key, const std::string& file) {
    if (!file.empty() && !std::filesystem::exists(file))
      throw SessionConfigError(session_file + ": " + key + " = \"" + file + "\": no such file");
  };
  exists("cameras.stereo_calibration", cameras.stereo_calibration);
  for (const auto& [side, cam] :
       {std::pair{"cameras.left", &cameras.left}, std::pair{"cameras.right", &cameras.right}}) {
    exists(std::string(side) + ".video", cam->video);
    exists(std::string(side) + ".calibration", cam->calibration);
    if (!cam->calibration.empty()) {
      try {
        vision::CameraModel::load(cam->calibration);
      } catch (const std::exception& error) {
        throw SessionConfigError(session_file + ": " + side + ".calibration: " + error.what());
      }
    }
    if (cam->device >= 0 && !std::filesystem::exists("/dev/video" + std::to_string(cam->device))) {
      throw SessionConfigError(session_file + ": " + side +
                               ".device = " + std::to_string(cam->device) + ": /dev/video" +
                               std::to_string(cam->device) + " does not exist");
    }
  }
}

core::Registry<SceneFactory>& sceneSources() {
  static core::Registry<SceneFactory> registry = [] {
    core::Registry<SceneFactory> r("camera source", "cameras.source");
    r.add({"simulated",
           "the simulated world: the session's table, objects and reference marker rendered for "
           "a stereo rig at the subject's head (cameras.width ... blur_px)",
           makeSimulatedScene});
    r.add({"devices", "camera devices (V4L2) or video files, each with its calibration",
           [](const SceneSettings& s) { return std::make_unique<DeviceScene>(s); }});
    return r;
  }();
  return registry;
}

}  // namespace arbci::session
