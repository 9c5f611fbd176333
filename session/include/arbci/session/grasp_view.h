// Private: how well the cameras kept an object in view while the arm came down on it. From the
// GRASP's start until the arm holds the object (or the command ends), the object's tracked pose
// should stay fresh: the gripper's fingers over a corner of its marker must not lose it. The
// paradigm stage feeds it every cycle and files what it saw with the trial.
#pragma once

#include <optional>

#include "arbci/session/cycle.h"

namespace arbci::session {

struct GraspSight {
  int object = 0;
  double seconds = 0.0;     // from the GRASP's start until the arm held the object
  double max_age_s = 0.0;   // the oldest the object's tracked pose grew meanwhile
  bool never_seen = false;  // the object had no tracked pose at some point of it
};

class GraspView {
 public:
  // One cycle's robot status and tracking, at session time `t`.
  void observe(double t, const RobotPart& robot, const TrackingPart& tracking);
  // The grasp that ended since the last call, once.
  std::optional<GraspSight> take();

 private:
  std::optional<GraspSight> watching_, ended_;
  double started_s_ = 0.0;
};

}  // namespace arbci::session
