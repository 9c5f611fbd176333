#include "arbci/vision/world_model.h"

#include <cstdio>

namespace arbci::vision {

WorldModel::WorldModel(ReferenceMarker reference) : reference_(reference) {}

std::vector<int> WorldModel::update(double time_s,
                                    const std::map<int, PoseEstimate>& camera_poses) {
  std::vector<int> updated;
  const auto reference = camera_poses.find(reference_.id);
  if (reference == camera_poses.end()) return updated;
  // T_robot_cam = T_robot_ref * inverse(T_cam_ref)
  const Pose T_robot_cam = reference_.T_robot_ref * reference->second.pose.inverse();
  robot_cam_ = T_robot_cam;
  reference_seen_at_ = time_s;
  for (const auto& [id, estimate] : camera_poses) {
    if (id == reference_.id) continue;
    objects_[id] = {id, T_robot_cam * estimate.pose, time_s, estimate.reprojection_rms_px};
    updated.push_back(id);
  }
  return updated;
}

void WorldModel::forget(int id) {
  objects_.erase(id);
}

std::optional<ObjectState> WorldModel::object(int id) const {
  const auto found = objects_.find(id);
  if (found == objects_.end()) return std::nullopt;
  return found->second;
}

std::vector<ObjectState> WorldModel::objects() const {
  std::vector<ObjectState> all;
  for (const auto& [id, state] : objects_) all.push_back(state);
  return all;
}

std::optional<double> WorldModel::referenceAge(double now_s) const {
  if (reference_seen_at_ < 0.0) return std::nullopt;
  return now_s - reference_seen_at_;
}

bool WorldModel::referenceVisible(double now_s, double max_age_s) const {
  return reference_seen_at_ >= 0.0 && now_s - reference_seen_at_ <= max_age_s;
}

std::string WorldModel::status(double now_s) const {
  char text[160];
  if (reference_seen_at_ < 0.0) {
    std::snprintf(text, sizeof text, "reference marker %d not seen yet: no robot-frame poses",
                  reference_.id);
  } else if (!referenceVisible(now_s)) {
    std::snprintf(text, sizeof text,
                  "reference marker %d not seen for %.1f s: object poses are that old",
                  reference_.id, now_s - reference_seen_at_);
  } else {
    std::snprintf(text, sizeof text, "reference marker %d visible; %zu objects tracked",
                  reference_.id, objects_.size());
  }
  return text;
}

}  // namespace arbci::vision
