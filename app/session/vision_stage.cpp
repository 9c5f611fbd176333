#include "session/vision_stage.h"

#include <memory>

#include "arbci/vision/undistortion.h"

namespace arbci::app {
namespace {

vision::DetectorConfig detectorFor(const SessionConfig& config, const vision::CameraModel& camera) {
  vision::DetectorConfig d;
  d.kind = vision::markerKindFromString(config.tracker_kind);
  d.border = config.tracker_border;
  if (!camera.distortion.empty())
    d.lens = std::make_shared<vision::Undistorter>(camera, vision::UndistortMode::LookupTable);
  return d;
}

vision::ReferenceMarker referenceOf(const SessionConfig& config) {
  vision::ReferenceMarker r;
  r.id = config.world.reference_id;
  r.size_m = config.world.reference_size_m;
  r.T_robot_ref = {cv::Matx33d::eye(), config.world.reference_position};
  return r;
}

}  // namespace

VisionStage::VisionStage(const SessionConfig& config, const vision::CameraModel& left,
                         const vision::CameraModel& right, const vision::Pose& T_right_left)
    : config_(config),
      reference_id_(config.world.reference_id),
      reference_size_m_(config.world.reference_size_m),
      left_camera_(left),
      right_camera_(right),
      T_right_left_(T_right_left),
      detector_(detectorFor(config, left)),
      poses_(left.camera_matrix),
      world_(referenceOf(config)) {}

void VisionStage::setReference(int id, double size_m, const cv::Vec3d& position) {
  vision::ReferenceMarker reference;
  reference.id = id;
  reference.size_m = size_m;
  reference.T_robot_ref = {cv::Matx33d::eye(), position};
  reference_id_ = id;
  reference_size_m_ = size_m;
  world_ = vision::WorldModel(reference);
  poses_.clear();
  last_poses_.clear();
}

double VisionStage::markerSize(int id) const {
  if (id == reference_id_) return reference_size_m_;
  for (const WorldObjectSettings& o : config_.world.objects) {
    if (o.id == id) return o.marker_m;
  }
  return 0.0;
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
