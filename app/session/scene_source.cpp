#include "session/scene_source.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "session/camera_capture.h"
#include "session/simulated_world.h"

namespace arbci::app {
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
  return {config.cameras,  config.world,      config.tracker_kind,       config.tracker_border,
          config.eeg.seed, config.display_hz, config.robot_speed_factor, config.source};
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

std::unique_ptr<SceneSource> openScene(const SceneSettings& settings) {
  if (settings.cameras.source == "simulated") return std::make_unique<SimulatedScene>(settings);
  return std::make_unique<DeviceScene>(settings);
}

}  // namespace arbci::app
