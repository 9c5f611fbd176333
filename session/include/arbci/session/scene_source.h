// What the session's cameras look at, behind one interface: the simulated world (rendered table,
// objects that follow the simulated arm, a head that moves) or the real scene through two camera
// devices or video files. The cycle asks for this frame's images and never asks which it is.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/core/registry.h"
#include "arbci/robot/protocol.h"
#include "arbci/robot/robot_config.h"
#include "arbci/session/session_config.h"
#include "arbci/vision/camera_model.h"
#include "arbci/vision/marker.h"
#include "arbci/vision/pose.h"

namespace arbci::session {

// What the scene needs of the session file, and nothing else.
struct SceneSettings {
  CameraSettings cameras;
  WorldSettings world;             // a simulated scene builds its table from it
  vision::MarkerKind marker_kind;  // the simulated world's markers
  double marker_border;
  std::uint64_t seed;         // the simulated cameras' noise
  double display_hz;          // display frames per camera frame
  double robot_speed_factor;  // the simulated arm's
  std::string session_file;   // for messages naming a key
  static SceneSettings of(const SessionConfig& config);
  // Before the run: the files and devices named can be opened; throws SessionConfigError naming
  // the key and the value.
  void validate() const;
};

class SceneSource {
 public:
  virtual ~SceneSource() = default;
  const vision::CameraModel& leftCamera() const { return left_camera_; }
  const vision::CameraModel& rightCamera() const { return right_camera_; }
  const vision::Pose& T_right_left() const { return T_right_left_; }

  struct Frames {
    cv::Mat left;              // a new left frame (empty: none this cycle)
    bool left_changed = true;  // false: the same picture as the last left frame
    cv::Mat right;             // a new right frame (empty: none this cycle)
    bool any() const { return !left.empty() || !right.empty(); }
  };
  // This display frame's camera images, at session time `time_s`; `robot` is the robot's latest
  // report of its world (a simulated scene puts its objects and gripper there).
  virtual Frames capture(std::int64_t frame, double time_s,
                         const std::optional<robot::StatusPayload>& robot) = 0;
  // Left and right images to warm the tracker up with before the cycle is timed (none: nothing).
  virtual std::vector<std::pair<cv::Mat, cv::Mat>> warmUpFrames() { return {}; }
  // The objects a simulated arm should know (the simulated scene's); none for a real scene.
  virtual robot::RobotConfig simulatedRobot() const { return {}; }
  // A simulated scene can hold a chessboard up for calibration (a new pose each call).
  virtual bool canHoldBoard() const { return false; }
  virtual void holdBoard(bool /*show*/, double /*time_s*/) {}

 protected:
  vision::CameraModel left_camera_, right_camera_;
  vision::Pose T_right_left_;
};

// The camera sources by cameras.source: "simulated" (the simulated world, drawn on the CPU) and
// "devices" (camera devices or video files). A factory throws
// SessionConfigError naming the key when its cameras cannot be opened.
using SceneFactory = std::function<std::unique_ptr<SceneSource>(const SceneSettings&)>;
core::Registry<SceneFactory>& sceneSources();

}  // namespace arbci::session
