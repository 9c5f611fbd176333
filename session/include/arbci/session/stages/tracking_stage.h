// Tracking: the markers of each new left camera frame (lens-aware), their poses turned into
// robot-frame poses through the reference marker, and each eye's camera pose in the robot frame
// for the HMD overlays (the right one through the rig's extrinsics). An object the robot moved
// is forgotten until a frame shows it again. The experimenter's threshold and reference marker
// (the panels) apply from the next frame.
#pragma once

#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "arbci/session/stage.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_poses.h"
#include "arbci/vision/world_model.h"

namespace arbci::session {

struct TrackingSettings {
  // The session's tracker settings, whole (kind, border, search_decimate, passes, ...); the
  // stage adds the left camera's lens.
  vision::DetectorConfig detector;
  int reference_id;
  double reference_size_m;
  cv::Vec3d reference_position;       // robot frame
  std::map<int, double> marker_size;  // the objects' marker sides (metres) by id
  double max_pose_age_s;              // older poses are stale
  // The cameras (the scene's): their models, the right camera's pose in the left's frame, and
  // frames to warm the tracker up with before the cycle is timed.
  vision::CameraModel left_camera, right_camera;
  vision::Pose T_right_left;
  std::vector<std::pair<cv::Mat, cv::Mat>> warm_up;
};

class TrackingStage final : public Stage {
 public:
  TrackingStage(TrackingSettings settings, const StageServices& services);
  const char* name() const override { return "tracking"; }
  void step(Cycle& cycle) override;
  // What tracking knows now.
  void publish(TrackingPart& out) const;

 private:
  void process(double t, const cv::Mat& left, const cv::Mat& right);
  void take(double t, const CameraPart& frames);
  void setReference(const ReferenceRequest& request, Cycle& cycle);
  double markerSize(int id) const;

  TrackingSettings settings_;
  StageServices s_;
  vision::MarkerDetector detector_;
  vision::MarkerPoses poses_;
  vision::WorldModel world_;
  std::map<int, vision::PoseEstimate> last_poses_;
  vision::DetectionResult last_;
  cv::Mat left_image_, right_image_;
};

}  // namespace arbci::session
