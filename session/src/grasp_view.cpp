#include "arbci/session/grasp_view.h"

#include <algorithm>

#include "arbci/vision/world_model.h"

namespace arbci::session {

void GraspView::observe(double t, const RobotPart& robot, const TrackingPart& tracking) {
  const bool coming_down = robot.status && robot.grasped &&
                           robot.status->current_command == robot::MessageType::Grasp &&
                           robot.status->holding != *robot.grasped;
  if (!coming_down) {
    if (watching_) {
      watching_->seconds = t - started_s_;
      ended_ = watching_;
      watching_.reset();
    }
    return;
  }
  if (!watching_ || watching_->object != *robot.grasped) {
    watching_ = GraspSight{.object = *robot.grasped};
    started_s_ = t;
  }
  const auto state = tracking.world ? tracking.world->object(watching_->object) : std::nullopt;
  if (!state)
    watching_->never_seen = true;
  else
    watching_->max_age_s = std::max(watching_->max_age_s, state->age(t));
}

std::optional<GraspSight> GraspView::take() {
  std::optional<GraspSight> out = ended_;
  ended_.reset();
  return out;
}

}  // namespace arbci::session
