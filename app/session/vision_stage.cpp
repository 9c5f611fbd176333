#include "session/vision_stage.h"

#include <cstdio>

#include <memory>

#include "arbci/vision/undistortion.h"

namespace arbci::app {
namespace {

vision::DetectorConfig detectorFor(const TrackingSettings& settings,
                                   const vision::CameraModel& camera) {
  vision::DetectorConfig d;
  d.kind = settings.kind;
  d.border = settings.border;
  d.search_decimate = settings.search_decimate;
  if (!camera.distortion.empty())
    d.lens = std::make_shared<vision::Undistorter>(camera, vision::UndistortMode::LookupTable);
  return d;
}

vision::ReferenceMarker referenceOf(const TrackingSettings& settings) {
  vision::ReferenceMarker r;
  r.id = settings.reference_id;
  r.size_m = settings.reference_size_m;
  r.T_robot_ref = {cv::Matx33d::eye(), settings.reference_position};
  return r;
}

}  // namespace

TrackingSettings TrackingSettings::of(const SessionConfig& config) {
  TrackingSettings t{vision::markerKindFromString(config.tracker_kind),
                     config.tracker_border,
                     config.tracker_search_decimate,
                     config.world.reference_id,
                     config.world.reference_size_m,
                     config.world.reference_position,
                     {},
                     config.max_pose_age_s};
  for (const WorldObjectSettings& o : config.world.objects) t.marker_size[o.id] = o.marker_m;
  return t;
}

bool VisionStage::fresh(int id, double now_s) const {
  const auto state = world_.object(id);
  return state && state->age(now_s) <= settings_.max_pose_age_s;
}

std::string VisionStage::trackingAlarm(const std::vector<int>& ids, double now_s) const {
  std::string lost;
  auto add = [&lost](const std::string& what, std::optional<double> age) {
    char text[64];
    if (age) {
      std::snprintf(text, sizeof text, " (%.1f s)", *age);
    } else {
      std::snprintf(text, sizeof text, " (never seen)");
    }
    lost.append(lost.empty() ? "" : ", ").append(what).append(text);
  };
  const auto reference = world_.referenceAge(now_s);
  if (!reference || *reference > settings_.max_pose_age_s)
    add("reference " + std::to_string(world_.reference().id), reference);
  for (int id : ids) {
    const auto state = world_.object(id);
    if (!state || state->age(now_s) > settings_.max_pose_age_s)
      add("object " + std::to_string(id),
          state ? std::optional<double>(state->age(now_s)) : std::nullopt);
  }
  return lost.empty() ? "" : "tracking lost: " + lost;
}

VisionStage::VisionStage(const TrackingSettings& settings, CameraStage& cameras)
    : settings_(settings),
      cameras_(cameras),
      left_camera_(cameras.scene().leftCamera()),
      right_camera_(cameras.scene().rightCamera()),
      T_right_left_(cameras.scene().T_right_left()),
      detector_(detectorFor(settings, left_camera_)),
      poses_(left_camera_.camera_matrix),
      world_(referenceOf(settings)) {
  for (const auto& [left, right] : cameras.scene().warmUpFrames()) process(0.0, left, right);
}

void VisionStage::step(CycleContext& cycle) {
  if (cameras_.frames().any()) take(cycle.time_s, cameras_.frames());
}

void VisionStage::setReference(int id, double size_m, const cv::Vec3d& position) {
  vision::ReferenceMarker reference;
  reference.id = id;
  reference.size_m = size_m;
  reference.T_robot_ref = {cv::Matx33d::eye(), position};
  settings_.reference_id = id;
  settings_.reference_size_m = size_m;
  settings_.reference_position = position;
  world_ = vision::WorldModel(reference);
  poses_.clear();
  last_poses_.clear();
}

double VisionStage::markerSize(int id) const {
  if (id == settings_.reference_id) return settings_.reference_size_m;
  const auto found = settings_.marker_size.find(id);
  return found == settings_.marker_size.end() ? 0.0 : found->second;
}

void VisionStage::process(double t, const cv::Mat& left, const cv::Mat& right) {
  left_image_ = left;
  if (!right.empty()) right_image_ = right;
  last_ = detector_.detect(left);
  std::map<int, vision::PoseEstimate> poses =
      poses_.estimate(last_.markers, [this](int id) { return markerSize(id); });
  world_.update(t, poses);
  last_poses_ = std::move(poses);
}

void VisionStage::take(double t, const SceneSource::Frames& frames) {
  if (frames.left.empty()) {
    if (!frames.right.empty()) right_image_ = frames.right;
  } else if (frames.left_changed) {
    process(t, frames.left, frames.right);
  } else {
    repeat(t);
    if (!frames.right.empty()) right_image_ = frames.right;
  }
}

void VisionStage::repeat(double t) {
  world_.update(t, last_poses_);
}

void VisionStage::objectMoved(int id) {
  world_.forget(id);
  poses_.forget(id);
  last_poses_.erase(id);
}

std::optional<vision::Pose> VisionStage::T_cam_world_left() const {
  const auto T_robot_cam = world_.T_robot_cam();
  if (!T_robot_cam) return std::nullopt;
  return T_robot_cam->inverse();
}

std::optional<vision::Pose> VisionStage::T_cam_world_right() const {
  const auto left = T_cam_world_left();
  if (!left) return std::nullopt;
  return T_right_left_ * *left;
}

}  // namespace arbci::app
