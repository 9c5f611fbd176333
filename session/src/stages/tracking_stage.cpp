#include "arbci/session/stages/tracking_stage.h"

#include "arbci/vision/undistortion.h"

namespace arbci::session {
namespace {

vision::DetectorConfig detectorFor(const TrackingSettings& settings) {
  vision::DetectorConfig d = settings.detector;
  // The markers the session looks for: the costliest search pass runs only when one is missed.
  d.expected_ids = {settings.reference_id};
  for (const auto& [id, size] : settings.marker_size) d.expected_ids.insert(id);
  if (!settings.left_camera.distortion.empty())
    d.lens = std::make_shared<vision::Undistorter>(settings.left_camera,
                                                   vision::UndistortMode::LookupTable);
  return d;
}

vision::ReferenceMarker referenceOf(int id, double size_m, const cv::Vec3d& position) {
  vision::ReferenceMarker r;
  r.id = id;
  r.size_m = size_m;
  r.T_robot_ref = {cv::Matx33d::eye(), position};
  return r;
}

}  // namespace

TrackingStage::TrackingStage(TrackingSettings settings, const StageServices& services)
    : settings_(std::move(settings)),
      s_(services),
      detector_(detectorFor(settings_)),
      poses_(settings_.left_camera.camera_matrix),
      world_(referenceOf(settings_.reference_id, settings_.reference_size_m,
                         settings_.reference_position)) {
  // The tracker builds its tables on first use: before the cycle is timed.
  for (const auto& [left, right] : settings_.warm_up) process(0.0, left, right);
  settings_.warm_up.clear();
}

double TrackingStage::markerSize(int id) const {
  if (id == settings_.reference_id) return settings_.reference_size_m;
  const auto found = settings_.marker_size.find(id);
  return found == settings_.marker_size.end() ? 0.0 : found->second;
}

void TrackingStage::process(double t, const cv::Mat& left, const cv::Mat& right) {
  left_image_ = left;
  if (!right.empty()) right_image_ = right;
  last_ = detector_.detect(left);
  std::map<int, vision::PoseEstimate> poses =
      poses_.estimate(last_.markers, [this](int id) { return markerSize(id); });
  world_.update(t, poses);
  last_poses_ = std::move(poses);
}

void TrackingStage::take(double t, const CameraPart& frames) {
  if (frames.left.empty()) {
    if (!frames.right.empty()) right_image_ = frames.right;
  } else if (frames.left_changed) {
    process(t, frames.left, frames.right);
  } else {
    // The same picture as last time: the last poses are seen again without tracking.
    world_.update(t, last_poses_);
    if (!frames.right.empty()) right_image_ = frames.right;
  }
}

void TrackingStage::setReference(const ReferenceRequest& request, Cycle& cycle) {
  settings_.reference_id = request.id;
  settings_.reference_position = request.position;
  world_ =
      vision::WorldModel(referenceOf(request.id, settings_.reference_size_m, request.position));
  poses_.clear();
  last_poses_.clear();
  s_.log.write("reference", cycle.time_s,
               {{"id", request.id},
                {"position", {request.position[0], request.position[1], request.position[2]}}});
}

void TrackingStage::step(Cycle& cycle) {
  for (const Request& request : cycle.record.requests) {
    if (const auto* r = std::get_if<ThresholdRequest>(&request)) {
      detector_.setThreshold(r->threshold);
      settings_.detector.threshold = r->threshold;
    } else if (const auto* r = std::get_if<ReferenceRequest>(&request)) {
      setReference(*r, cycle);
    }
  }
  if (cycle.record.cameras.any()) take(cycle.time_s, cycle.record.cameras);
  // What the robot moved this cycle is unknown until a frame shows it again.
  for (int id : cycle.record.robot.moved) {
    world_.forget(id);
    poses_.forget(id);
    last_poses_.erase(id);
  }
  publish(cycle.record.tracking);
}

void TrackingStage::publish(TrackingPart& out) const {
  out.left_image = left_image_;
  out.right_image = right_image_.empty() ? left_image_ : right_image_;
  out.stereo = !right_image_.empty();
  out.left_camera = settings_.left_camera;
  out.right_camera = right_image_.empty() ? settings_.left_camera : settings_.right_camera;
  out.detection = last_;
  out.binary = detector_.lastBinaryImage();
  out.threshold = settings_.detector.threshold;
  out.world = std::make_shared<const vision::WorldModel>(world_);
  out.max_pose_age_s = settings_.max_pose_age_s;
  out.T_cam_world_left.reset();
  out.T_cam_world_right.reset();
  if (const auto T_robot_cam = world_.T_robot_cam()) {
    out.T_cam_world_left = T_robot_cam->inverse();
    out.T_cam_world_right = settings_.T_right_left * *out.T_cam_world_left;
  }
}

}  // namespace arbci::session
