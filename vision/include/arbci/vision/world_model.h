// The robot-frame world: a reference marker at a known pose in the robot's frame turns every
// other marker's camera pose into a robot-frame pose,
//   T_robot_marker = T_robot_ref * inverse(T_cam_ref) * T_cam_marker,
// as the original system did (the reference 0.90 m along the robot's y axis by default). The
// model keeps each object's latest robot-frame pose with its age, and says plainly when the
// reference marker is not visible.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arbci/vision/pose.h"

namespace arbci::vision {

struct ReferenceMarker {
  int id = 0;
  double size_m = 0.0;  // its black square's side (a session's world.reference.size_m)
  // The reference marker's frame in the robot's frame: by default lying flat on the table with
  // its x and y along the robot's, 0.90 m along the robot's y axis.
  Pose T_robot_ref{cv::Matx33d::eye(), cv::Vec3d(0.0, 0.90, 0.0)};
};

struct ObjectState {
  int id = 0;
  Pose T_robot_object;
  double seen_at_s = 0.0;
  double reprojection_rms_px = 0.0;
  double age(double now_s) const { return now_s - seen_at_s; }
};

class WorldModel {
 public:
  explicit WorldModel(ReferenceMarker reference = {});

  // One camera's marker poses of one frame (T_cam_marker by marker id; the reference among them
  // if it was seen). Without the reference, the objects keep their last poses and grow older.
  // Returns the ids whose robot-frame pose this frame updated.
  std::vector<int> update(double time_s, const std::map<int, PoseEstimate>& camera_poses);

  // The object has been moved (by the robot): its pose is unknown until the cameras see it again.
  void forget(int id);

  std::optional<ObjectState> object(int id) const;
  std::vector<ObjectState> objects() const;
  bool referenceVisible(double now_s, double max_age_s = 0.5) const;
  // Seconds since the reference marker was last seen; nullopt: never.
  std::optional<double> referenceAge(double now_s) const;
  // The camera's pose in the robot frame from the last reference sighting.
  std::optional<Pose> T_robot_cam() const { return robot_cam_; }
  // A line for the experimenter, e.g. "reference marker 0 not seen for 2.4 s: object poses are 2.4
  // s old".
  std::string status(double now_s) const;
  const ReferenceMarker& reference() const { return reference_; }

 private:
  ReferenceMarker reference_;
  std::optional<Pose> robot_cam_;
  double reference_seen_at_ = -1.0;
  std::map<int, ObjectState> objects_;
};

}  // namespace arbci::vision
