// The camera half of the cycle: tracks the markers of the left camera's frames (lens-aware), turns
// them into robot-frame poses through the reference marker, and gives each eye's camera pose in
// the robot frame for the HMD overlays (the right one through the rig's extrinsics).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_poses.h"
#include "arbci/vision/world_model.h"
#include "session/camera_stage.h"
#include "session/session_config.h"
#include "session/stage.h"

namespace arbci::app {

// What tracking needs of the session file, and nothing else.
struct TrackingSettings {
  vision::MarkerKind kind;
  double border;        // of the markers' black square, as a fraction of its side
  int search_decimate;  // vision::DetectorConfig::search_decimate
  int reference_id;
  double reference_size_m;
  cv::Vec3d reference_position;       // robot frame
  std::map<int, double> marker_size;  // the objects' marker sides (metres) by id
  double max_pose_age_s;              // older poses are stale
  static TrackingSettings of(const SessionConfig& config);
};

class VisionStage final : public Stage {
 public:
  // Tracks what `cameras` capture; warms the tracker up on the scene's warm-up frames first (the
  // tracker builds its tables on first use, before the cycle is timed).
  VisionStage(const TrackingSettings& settings, CameraStage& cameras);

  const char* name() const override { return "tracking"; }
  void step(CycleContext& cycle) override;

  // A new pair of frames at time `t` (seconds); the right one may be empty (mono).
  void process(double t, const cv::Mat& left, const cv::Mat& right);
  // What the scene delivered this cycle: a new left frame is tracked (an unchanged one counts as
  // seen again), a right one is kept for the HMD.
  void take(double t, const SceneSource::Frames& frames);
  // The robot has moved object `id`: its pose is unknown until a new frame shows it.
  void objectMoved(int id);

  const cv::Mat& leftImage() const { return left_image_; }
  const cv::Mat& rightImage() const { return right_image_.empty() ? left_image_ : right_image_; }
  bool stereo() const { return !right_image_.empty(); }
  const vision::CameraModel& leftCamera() const { return left_camera_; }
  const vision::CameraModel& rightCamera() const {
    return right_image_.empty() ? left_camera_ : right_camera_;
  }
  std::optional<vision::Pose> T_cam_world_left() const;
  std::optional<vision::Pose> T_cam_world_right() const;
  const vision::WorldModel& world() const { return world_; }
  const vision::DetectionResult& lastDetection() const { return last_; }
  vision::MarkerDetector& detector() { return detector_; }
  // A new reference marker (id, position in the robot frame): object poses start afresh.
  void setReference(int id, double size_m, const cv::Vec3d& position);
  // Tracking health: the object's pose is known and no older than the allowed age.
  bool fresh(int id, double now_s) const;
  double maxPoseAgeS() const { return settings_.max_pose_age_s; }
  // "" while the reference and every object in `ids` are fresh, else "tracking lost: reference
  // 0 (2.1 s), object 40 (never seen)".
  std::string trackingAlarm(const std::vector<int>& ids, double now_s) const;
  // Marker side by id: the reference's or the object's.
  double markerSize(int id) const;

 private:
  // The same frames as last time, at time `t`: the last poses are seen again without tracking.
  void repeat(double t);
  TrackingSettings settings_;
  const CameraStage& cameras_;
  vision::CameraModel left_camera_, right_camera_;
  vision::Pose T_right_left_;
  vision::MarkerDetector detector_;
  vision::MarkerPoses poses_;
  vision::WorldModel world_;
  std::map<int, vision::PoseEstimate> last_poses_;
  vision::DetectionResult last_;
  cv::Mat left_image_, right_image_;
};

}  // namespace arbci::app
