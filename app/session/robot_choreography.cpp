#include "session/robot_choreography.h"

#include <nlohmann/json.hpp>

namespace arbci::app {

RobotChoreography::RobotChoreography(std::unique_ptr<robot::RobotClient> client, bool stepped,
                                     SessionLog& log, const WorldSettings& world,
                                     const render::GridLayout& grid, int camera_every, Hooks hooks)
    : client_(std::move(client)),
      stepped_(stepped),
      log_(log),
      world_(world),
      grid_(grid),
      camera_every_(camera_every),
      hooks_(std::move(hooks)) {}

void RobotChoreography::step(CycleContext& cycle) {
  const double time_s = cycle.time_s;
  // A stepped arm is moved to this frame's time while it has anything to do (idle, it does not
  // move; send() brings its clock up to date before a command).
  const bool matters = busy() || (homed_ && !clear_view_frame_) || placement_;
  if (stepped_ && matters && !client_->syncClock(time_s)) {
    stepped_ = false;
    log_.write("robot_clock_lost", time_s, {{"text", "the stepped robot backend did not answer"}});
  }
  client_->poll();
  handleEvents(time_s);
  measurePlacement(time_s);
  endPutDownOnceInView(cycle.frame);
}

void RobotChoreography::send(robot::MessageType type, const cv::Vec3d& target, double time_s) {
  if (stepped_) client_->syncClock(time_s);  // the command starts now, not at the last sync
  command_ = client_->send(type, {target[0], target[1], target[2]});
  command_type_ = type;
  if (type != robot::MessageType::Home) at_home_ = false;
}

void RobotChoreography::grasp(int object_id, const cv::Vec3d& at, double time_s) {
  grasped_id_ = object_id;
  grasped_from_ = at;
  send(robot::MessageType::Grasp, at, time_s);
  log_.write("robot_command", time_s,
             {{"command", "GRASP"},
              {"object", object_id},
              {"target", {at[0], at[1], at[2]}},
              {"sequence", *command_}});
}

void RobotChoreography::drop(std::pair<int, int> cell, bool give_back, double time_s) {
  giving_back_ = give_back;
  cv::Vec3d at = grid_.cellCentre(cell.first, cell.second);
  if (give_back) at = grasped_from_;
  at[2] = world_.table_z;
  send(robot::MessageType::Drop, at, time_s);
  log_.write("robot_command", time_s,
             {{"command", "DROP"},
              {"cell", {cell.first, cell.second}},
              {"target", {at[0], at[1], at[2]}},
              {"returning", give_back},
              {"sequence", *command_}});
}

void RobotChoreography::stop(double time_s) {
  const auto sequence = client_->send(robot::MessageType::Stop);
  command_.reset();  // the client cancelled it; the backend refuses it
  recovery_.reset();
  log_.write("robot_command", time_s, {{"command", "STOP"}, {"sequence", sequence}});
}

void RobotChoreography::reset(double time_s) {
  const auto sequence = client_->send(robot::MessageType::Reset);
  log_.write("robot_command", time_s,
             {{"command", "RESET"}, {"by", "experimenter"}, {"sequence", sequence}});
}

void RobotChoreography::resetIfLatched(double time_s) {
  const auto& status = client_->status();
  if (status && !status->stop_reason.empty()) reset(time_s);
}

void RobotChoreography::sendRecovery(robot::MessageType type, const cv::Vec3d& target,
                                     const char* what, double time_s) {
  resetIfLatched(time_s);
  if (stepped_) client_->syncClock(time_s);
  recovery_ = client_->send(type, {target[0], target[1], target[2]});
  recovery_type_ = type;
  if (type != robot::MessageType::Home) at_home_ = false;
  nlohmann::json fields = {{"command", robot::toString(type)},
                           {"by", "experimenter"},
                           {"what", what},
                           {"sequence", *recovery_}};
  if (type != robot::MessageType::Home) fields["target"] = {target[0], target[1], target[2]};
  log_.write("robot_command", time_s, fields);
  messages_.push_back(std::string("experimenter: ") + what);
}

void RobotChoreography::home(double time_s) {
  if (!whyNotMove().empty()) return;
  sendRecovery(robot::MessageType::Home, {}, "home", time_s);
}

void RobotChoreography::release(double time_s) {
  if (!whyNotRelease().empty()) return;
  cv::Vec3d at = grasped_from_;
  at[2] = world_.table_z;
  sendRecovery(robot::MessageType::Drop, at, "open the gripper where the object was taken from",
               time_s);
}

void RobotChoreography::finishPutDown(double time_s) {
  resetIfLatched(time_s);
  send(robot::MessageType::Home, {}, time_s);
  log_.write("robot_command", time_s,
             {{"command", "HOME"}, {"after", "an interrupted put-down"}, {"sequence", *command_}});
}

bool RobotChoreography::answersStatus(double time_s) {
  if (stepped_) return client_->syncClock(time_s, 0.5);
  return client_->status().has_value() && !client_->silent();
}

std::optional<int> RobotChoreography::holding() const {
  const auto& status = client_->status();
  if (!status || status->holding < 0) return std::nullopt;
  return status->holding;
}

std::string RobotChoreography::whyNotMove() const {
  if (client_->silent()) return "the robot backend does not answer";
  if (!client_->status()) return "no status from the robot backend yet";
  if (busy()) return "the arm is carrying out a command";
  return "";
}

std::string RobotChoreography::whyNotRelease() const {
  if (std::string why = whyNotMove(); !why.empty()) return why;
  const auto held = holding();
  if (!held) return "the gripper holds nothing";
  if (!grasped_id_ || *grasped_id_ != *held)
    return "object " + std::to_string(*held) +
           " was not grasped in this session: the place it came from is unknown";
  return "";
}

void RobotChoreography::handleRecoveryEvent(const robot::RobotEvent& e, double time_s) {
  using Kind = robot::RobotEvent::Kind;
  if (!recovery_ || e.sequence != *recovery_) return;
  if (e.kind != Kind::Finished && e.kind != Kind::Rejected && e.kind != Kind::Failed) return;
  recovery_.reset();
  client_->requestStatus();
  const bool success = e.kind == Kind::Finished && e.outcome == robot::Outcome::Success;
  if (!success) return;  // the messages say why; the experimenter decides again
  if (recovery_type_ == robot::MessageType::Home) {
    at_home_ = true;
    return;
  }
  // Released: the object stands where it was taken from; the cameras must see it anew, and the
  // arm goes home so they can.
  if (grasped_id_) hooks_.object_moved(*grasped_id_);
  grasped_id_.reset();
  sendRecovery(robot::MessageType::Home, {}, "home after opening the gripper", time_s);
}

bool RobotChoreography::measuring(double time_s) const {
  return placement_ && time_s - placement_since_ <= 3.0;
}

void RobotChoreography::handleEvents(double time_s) {
  using Kind = robot::RobotEvent::Kind;
  for (const robot::RobotEvent& e : client_->takeEvents()) {
    nlohmann::json fields = {{"kind", robot::toString(e.kind)},
                             {"sequence", e.sequence},
                             {"command", robot::toString(e.command)},
                             {"text", e.text}};
    if (e.kind == Kind::Rejected) fields["reason"] = robot::toString(e.reason);
    if (e.kind == Kind::Finished) fields["outcome"] = robot::toString(e.outcome);
    log_.write("robot", time_s, fields);
    // Link events (connected, silent, restarted) belong to no command.
    const std::string what =
        e.sequence == 0 ? std::string(robot::toString(e.kind))
                        : std::string(robot::toString(e.kind)) + " " + robot::toString(e.command);
    messages_.push_back(what + (e.text.empty() ? "" : ": " + e.text));
    if (messages_.size() > 200) messages_.erase(messages_.begin());
    handleRecoveryEvent(e, time_s);
    if (e.kind == Kind::Silent) recovery_.reset();
    if (!command_) continue;
    const bool ours = e.sequence == *command_;
    if (ours && e.kind == Kind::Finished) {
      command_.reset();
      client_->requestStatus();  // the world as the robot left it, without waiting
      const bool success = e.outcome == robot::Outcome::Success;
      if (success && command_type_ == robot::MessageType::Drop) {
        if (!giving_back_) {
          hooks_.current_trial().outcome = "placed";
          placement_ = std::make_pair(hooks_.current_trial().trial, e.sequence);
          placement_since_ = time_s;
        }
        hooks_.object_moved(*grasped_id_);
        // The arm parked over the table hides objects from the cameras: it goes home before the
        // next trial, and the put-down ends when it is there.
        send(robot::MessageType::Home, {}, time_s);
        log_.write("robot_command", time_s, {{"command", "HOME"}, {"sequence", *command_}});
        continue;
      }
      if (!success)
        hooks_.current_trial().outcome =
            std::string("robot ") + robot::toString(e.outcome) + ": " + e.text;
      if (success && command_type_ == robot::MessageType::Home) {
        at_home_ = true;
        homed_ = e.sequence;  // the put-down ends once the cameras have looked again
        continue;
      }
      hooks_.finished(success, e.text);
    } else if (ours && (e.kind == Kind::Rejected || e.kind == Kind::Failed)) {
      command_.reset();
      const std::string why =
          e.kind == Kind::Rejected
              ? std::string("rejected (") + robot::toString(e.reason) + "): " + e.text
              : e.text;
      hooks_.current_trial().outcome = "robot " + why;
      hooks_.finished(false, why);
    } else if (e.kind == Kind::Silent) {
      command_.reset();
      homed_.reset();
      hooks_.current_trial().outcome = "robot fault: the backend went silent";
      hooks_.finished(false, "the robot backend went silent (stopped or unreachable)");
    }
  }
}

void RobotChoreography::measurePlacement(double time_s) {
  const auto& status = client_->status();
  // Only a status that knows the drop finished shows where the object stands.
  if (!placement_ || !status || status->last_finished_sequence < placement_->second) return;
  TrialRecord& trial = hooks_.trial(placement_->first);
  for (const robot::WorldObject& o : status->objects) {
    if (!grasped_id_ || o.id != *grasped_id_) continue;
    double height = 0.0;
    for (const auto& s : world_.objects) {
      if (s.id == o.id) height = s.height_m;
    }
    const cv::Vec3d centre =
        grid_.cellCentre(trial.selected_cell.first, trial.selected_cell.second);
    trial.placement_error_m =
        cv::norm(cv::Vec3d(o.position.x, o.position.y, o.position.z - height) - centre);
    log_.write("placement", time_s,
               {{"trial", trial.trial},
                {"object", o.id},
                {"error_m", trial.placement_error_m},
                {"position", {o.position.x, o.position.y, o.position.z - height}}});
  }
  placement_.reset();
}

void RobotChoreography::endPutDownOnceInView(std::int64_t frame) {
  if (!homed_) return;
  if (!clear_view_frame_) {
    // The scene follows the robot's status: once it shows the arm home, two camera frames.
    const auto& status = client_->status();
    if (status && status->last_finished_sequence >= *homed_)
      clear_view_frame_ = frame + 2 * camera_every_ + 1;
    return;
  }
  if (frame < *clear_view_frame_) return;
  homed_.reset();
  clear_view_frame_.reset();
  hooks_.put_down_ended();
}

}  // namespace arbci::app
