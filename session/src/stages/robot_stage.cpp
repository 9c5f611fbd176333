#include "arbci/session/stages/robot_stage.h"

#include <cstdio>

#include <nlohmann/json.hpp>

namespace arbci::session {

RobotStage::RobotStage(const RobotStageSettings& settings, RobotLink link,
                       const StageServices& services)
    : settings_(settings),
      s_(services),
      link_(std::move(link)),
      client_(*link_.client),
      stepped_(link_.stepped),
      published_(std::make_shared<const std::vector<std::string>>()) {}

void RobotStage::step(Cycle& cycle) {
  const double time_s = cycle.time_s;
  RobotPart& out = cycle.record.robot;
  for (const Request& request : cycle.record.requests) act(request, cycle);
  // A stepped arm is moved to this frame's time while it has anything to do (idle, it does not
  // move; send() brings its clock up to date before a command).
  const bool matters = busy() || (homed_ && !clear_view_frame_) || placement_;
  if (stepped_ && matters && !client_.syncClock(time_s)) {
    stepped_ = false;
    s_.log.write("robot_clock_lost", time_s,
                 {{"text", "the stepped robot backend did not answer"}});
    s_.tell.say(time_s, Severity::Warning, "robot: the stepped backend did not answer");
  }
  client_.poll();
  handleEvents(out, time_s);
  noteReportedPlacement(time_s);
  // The robot acts before tracking in the cycle: the cameras' view is the last cycle's.
  endPutDownOnceInView(out, cycle.previous.tracking, time_s, cycle.frame);

  out.status = client_.status();
  out.silent = client_.silent();
  out.busy = busy();
  out.at_home = at_home_;
  out.measuring = placement_ && time_s - placement_->since_s <= 3.0;
  out.grasped = grasped_id_;
  out.answered = answered_;
  out.key_refused = client_.keyRefused();
  out.why_not_move = whyNotMove();
  out.why_not_release = whyNotRelease();
  if (messages_added_ != messages_published_) {
    published_ = std::make_shared<const std::vector<std::string>>(messages_);
    messages_published_ = messages_added_;
  }
  out.messages = published_;
}

void RobotStage::act(const Request& request, Cycle& cycle) {
  if (const auto* r = std::get_if<GraspRequest>(&request)) {
    grasp(*r, cycle.record.robot);
  } else if (const auto* r = std::get_if<DropRequest>(&request)) {
    drop(*r);
  } else if (const auto* r = std::get_if<RobotStopRequest>(&request)) {
    // The emergency stop already went out: nothing was sent since.
    if (!stopped_) stop(r->time_s);
  } else if (const auto* r = std::get_if<RobotResetRequest>(&request)) {
    reset(r->time_s);
  } else if (const auto* r = std::get_if<RobotResetIfLatchedRequest>(&request)) {
    resetIfLatched(r->time_s);
  } else if (const auto* r = std::get_if<RobotHomeRequest>(&request)) {
    home(r->time_s);
  } else if (const auto* r = std::get_if<RobotReleaseRequest>(&request)) {
    release(r->time_s);
  } else if (const auto* r = std::get_if<FinishPutDownRequest>(&request)) {
    finishPutDown(r->time_s);
  } else if (const auto* r = std::get_if<RobotProbeRequest>(&request)) {
    // A stepped backend is asked now (reproducibly); one on the wall clock has answered when it
    // has sent a status and is not silent.
    answered_ = stepped_ ? client_.syncClock(r->time_s, 0.5)
                         : client_.status().has_value() && !client_.silent();
  }
  (void)cycle;
}

void RobotStage::send(robot::MessageType type, const cv::Vec3d& target, double time_s) {
  if (stepped_) client_.syncClock(time_s);  // the command starts when asked, not at the last sync
  command_ = client_.send(type, {target[0], target[1], target[2]});
  command_type_ = type;
  stopped_ = false;
  if (type != robot::MessageType::Home) at_home_ = false;
}

std::string RobotStage::whyNotGrasp(const GraspRequest& r) const {
  if (r.at && r.pose_age_s > r.max_pose_age_s && holding() != r.object) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "object %d: tracking lost (pose %.1f s old), not grasped; Retry step once it is "
                  "seen again",
                  r.object, r.pose_age_s);
    return why;
  }
  if (!r.at)
    return "object " + std::to_string(r.object) +
           " is not in view (never seen, or not since the robot moved it)";
  return "";
}

void RobotStage::grasp(const GraspRequest& r, RobotPart& out) {
  using Note = RobotPart::Note;
  if (r.retry && holding() == r.object) {
    // Stopped after the gripper closed: the grasp is done.
    s_.log.write("robot_step_done", r.time_s, {{"step", "grasp"}, {"object", r.object}});
    out.notes.push_back({Note::Kind::Finished, true, ""});
    return;
  }
  if (const std::string why = whyNotGrasp(r); !why.empty()) {
    // Never a grasp at a stale or unknown position: the experimenter retries once it is seen.
    s_.log.write("robot_refused", r.time_s,
                 {{"command", "GRASP"}, {"object", r.object}, {"why", why}});
    if (r.at) s_.tell.say(r.time_s, Severity::Error, why);
    out.notes.push_back({Note::Kind::Outcome, false, why});
    out.notes.push_back({Note::Kind::Finished, false, why});
    return;
  }
  grasped_id_ = r.object;
  grasped_from_ = *r.at;
  send(robot::MessageType::Grasp, *r.at, r.time_s);
  s_.log.write("robot_command", r.time_s,
               {{"command", "GRASP"},
                {"object", r.object},
                {"target", {(*r.at)[0], (*r.at)[1], (*r.at)[2]}},
                {"sequence", *command_}});
}

void RobotStage::drop(const DropRequest& request) {
  giving_back_ = request.give_back;
  drop_ = request;
  cv::Vec3d at = settings_.world.grid.cellCentre(request.cell.first, request.cell.second);
  if (request.give_back) at = grasped_from_;
  at[2] = settings_.world.table_z;
  send(robot::MessageType::Drop, at, request.time_s);
  s_.log.write("robot_command", request.time_s,
               {{"command", "DROP"},
                {"cell", {request.cell.first, request.cell.second}},
                {"target", {at[0], at[1], at[2]}},
                {"returning", request.give_back},
                {"sequence", *command_}});
}

void RobotStage::stop(double time_s) {
  const auto sequence = client_.send(robot::MessageType::Stop);
  command_.reset();  // the client cancelled it; the backend refuses it
  recovery_.reset();
  stopped_ = true;
  s_.log.write("robot_command", time_s, {{"command", "STOP"}, {"sequence", sequence}});
}

void RobotStage::stop(Cycle& cycle, const std::string& reason) {
  if (!busy() || stopped_) return;
  s_.log.write("robot_stopped_at_end", cycle.time_s, {{"reason", reason}});
  stop(cycle.time_s);
  client_.poll();
}

void RobotStage::stopNow(double time_s) {
  stop(time_s);
}

void RobotStage::reset(double time_s) {
  const auto sequence = client_.send(robot::MessageType::Reset);
  s_.log.write("robot_command", time_s,
               {{"command", "RESET"}, {"by", "experimenter"}, {"sequence", sequence}});
}

void RobotStage::resetIfLatched(double time_s) {
  const auto& status = client_.status();
  if (status && !status->stop_reason.empty()) reset(time_s);
}

void RobotStage::sendRecovery(robot::MessageType type, const cv::Vec3d& target, const char* what,
                              double time_s) {
  resetIfLatched(time_s);
  if (stepped_) client_.syncClock(time_s);
  recovery_ = client_.send(type, {target[0], target[1], target[2]});
  recovery_type_ = type;
  stopped_ = false;
  if (type != robot::MessageType::Home) at_home_ = false;
  nlohmann::json fields = {{"command", robot::toString(type)},
                           {"by", "experimenter"},
                           {"what", what},
                           {"sequence", *recovery_}};
  if (type != robot::MessageType::Home) fields["target"] = {target[0], target[1], target[2]};
  s_.log.write("robot_command", time_s, fields);
  messages_.push_back(std::string("experimenter: ") + what);
  ++messages_added_;
}

void RobotStage::home(double time_s) {
  if (!whyNotMove().empty()) return;
  sendRecovery(robot::MessageType::Home, {}, "home", time_s);
}

void RobotStage::release(double time_s) {
  if (!whyNotRelease().empty()) return;
  cv::Vec3d at = grasped_from_;
  at[2] = settings_.world.table_z;
  sendRecovery(robot::MessageType::Drop, at, "open the gripper where the object was taken from",
               time_s);
}

void RobotStage::finishPutDown(double time_s) {
  resetIfLatched(time_s);
  send(robot::MessageType::Home, {}, time_s);
  s_.log.write(
      "robot_command", time_s,
      {{"command", "HOME"}, {"after", "an interrupted put-down"}, {"sequence", *command_}});
}

std::optional<int> RobotStage::holding() const {
  const auto& status = client_.status();
  if (!status || status->holding < 0) return std::nullopt;
  return status->holding;
}

std::string RobotStage::whyNotMove() const {
  if (client_.silent()) return "the robot backend does not answer";
  if (!client_.status()) return "no status from the robot backend yet";
  if (busy()) return "the arm is carrying out a command";
  return "";
}

std::string RobotStage::whyNotRelease() const {
  if (std::string why = whyNotMove(); !why.empty()) return why;
  const auto held = holding();
  if (!held) return "the gripper holds nothing";
  if (!grasped_id_ || *grasped_id_ != *held)
    return "object " + std::to_string(*held) +
           " was not grasped in this session: the place it came from is unknown";
  return "";
}

void RobotStage::handleRecoveryEvent(const robot::RobotEvent& e, RobotPart& out, double time_s) {
  using Kind = robot::RobotEvent::Kind;
  if (!recovery_ || e.sequence != *recovery_) return;
  if (e.kind != Kind::Finished && e.kind != Kind::Rejected && e.kind != Kind::Failed) return;
  recovery_.reset();
  client_.requestStatus();
  const bool success = e.kind == Kind::Finished && e.outcome == robot::Outcome::Success;
  if (!success) return;  // the messages say why; the experimenter decides again
  if (recovery_type_ == robot::MessageType::Home) {
    at_home_ = true;
    return;
  }
  // Released: the object stands where it was taken from; the cameras must see it anew, and the
  // arm goes home so they can.
  if (grasped_id_) out.moved.push_back(*grasped_id_);
  grasped_id_.reset();
  sendRecovery(robot::MessageType::Home, {}, "home after opening the gripper", time_s);
}

void RobotStage::handleEvents(RobotPart& out, double time_s) {
  using Kind = robot::RobotEvent::Kind;
  using Note = RobotPart::Note;
  for (const robot::RobotEvent& e : client_.takeEvents()) {
    nlohmann::json fields = {{"kind", robot::toString(e.kind)},
                             {"sequence", e.sequence},
                             {"command", robot::toString(e.command)},
                             {"text", e.text}};
    if (e.kind == Kind::Rejected) fields["reason"] = robot::toString(e.reason);
    if (e.kind == Kind::Finished) fields["outcome"] = robot::toString(e.outcome);
    if (e.kind == Kind::Failed) fields["may_have_run"] = e.may_have_run;
    // How the heartbeat that keeps the backend's watchdog quiet is scheduled.
    if (e.kind == Kind::Connected) fields["heartbeat_priority"] = client_.heartbeatPriority();
    s_.log.write("robot", time_s, fields);
    // Link events (connected, silent, restarted) belong to no command.
    const std::string what =
        e.sequence == 0 ? std::string(robot::toString(e.kind))
                        : std::string(robot::toString(e.kind)) + " " + robot::toString(e.command);
    messages_.push_back(what + (e.text.empty() ? "" : ": " + e.text));
    const bool bad = e.kind == Kind::Rejected || e.kind == Kind::Failed || e.kind == Kind::Silent ||
                     (e.kind == Kind::Finished && e.outcome != robot::Outcome::Success);
    if (bad) s_.tell.say(time_s, Severity::Error, "robot: " + messages_.back());
    ++messages_added_;
    if (messages_.size() > 200) messages_.erase(messages_.begin());
    handleRecoveryEvent(e, out, time_s);
    if (e.kind == Kind::Silent) recovery_.reset();
    if (!command_) continue;
    const bool ours = e.sequence == *command_;
    if (ours && e.kind == Kind::Finished) {
      command_.reset();
      client_.requestStatus();  // the world as the robot left it, without waiting
      const bool success = e.outcome == robot::Outcome::Success;
      if (success && command_type_ == robot::MessageType::Drop) {
        if (!giving_back_ && drop_) {
          out.notes.push_back({Note::Kind::Outcome, true, "placed"});
          placement_ = Placement{drop_->trial, drop_->cell, e.sequence, time_s, std::nullopt};
        }
        out.moved.push_back(*grasped_id_);
        // The arm parked over the table hides objects from the cameras: it goes home before the
        // next trial, and the put-down ends when it is there.
        send(robot::MessageType::Home, {}, time_s);
        s_.log.write("robot_command", time_s, {{"command", "HOME"}, {"sequence", *command_}});
        continue;
      }
      if (!success)
        out.notes.push_back({Note::Kind::Outcome, false,
                             std::string("robot ") + robot::toString(e.outcome) + ": " + e.text});
      if (success && command_type_ == robot::MessageType::Home) {
        at_home_ = true;
        homed_ = e.sequence;  // the put-down ends once the cameras have looked again
        continue;
      }
      out.notes.push_back({Note::Kind::Finished, success, e.text});
    } else if (ours && (e.kind == Kind::Rejected || e.kind == Kind::Failed)) {
      command_.reset();
      const std::string why =
          e.kind == Kind::Rejected
              ? std::string("rejected (") + robot::toString(e.reason) + "): " + e.text
              : e.text;
      out.notes.push_back({Note::Kind::Outcome, false, "robot " + why});
      out.notes.push_back({Note::Kind::Finished, false, why});
    } else if (e.kind == Kind::Silent) {
      command_.reset();
      homed_.reset();
      out.notes.push_back({Note::Kind::Outcome, false, "robot fault: the backend went silent"});
      out.notes.push_back(
          {Note::Kind::Finished, false, "the robot backend went silent (stopped or unreachable)"});
    }
  }
}

double RobotStage::objectHeight(int id) const {
  for (const auto& s : settings_.world.objects) {
    if (s.id == id) return s.height_m;
  }
  return 0.0;
}

void RobotStage::noteReportedPlacement(double time_s) {
  const auto& status = client_.status();
  // Only a status that knows the drop finished shows where the robot let the object go.
  if (!placement_ || placement_->reported || !grasped_id_ || !status ||
      status->last_finished_sequence < placement_->command)
    return;
  for (const robot::WorldObject& o : status->objects) {
    if (o.id != *grasped_id_) continue;
    placement_->reported = cv::Vec3d(o.position.x, o.position.y, o.position.z - objectHeight(o.id));
    s_.log.write(
        "placement_reported", time_s,
        {{"trial", placement_->trial},
         {"object", o.id},
         {"position",
          {(*placement_->reported)[0], (*placement_->reported)[1], (*placement_->reported)[2]}}});
  }
}

void RobotStage::measurePlacement(RobotPart& out, const TrackingPart& tracking, double time_s) {
  if (!placement_ || !grasped_id_) return;
  const int id = *grasped_id_;
  const cv::Vec3d centre =
      settings_.world.grid.cellCentre(placement_->cell.first, placement_->cell.second);
  RobotPart::Note note{RobotPart::Note::Kind::Placement, true, ""};
  note.trial = placement_->trial;
  note.error_m = -1.0;  // not seen
  nlohmann::json fields = {{"trial", placement_->trial}, {"object", id}};
  // The object's top as the cameras saw it after the drop (the tracker forgot it when the robot
  // moved it, so any pose it has now is a new sighting).
  const auto seen = tracking.world ? tracking.world->object(id) : std::nullopt;
  if (seen && seen->seen_at_s >= placement_->since_s) {
    const cv::Vec3d top = seen->T_robot_object.translation;
    const cv::Vec3d base(top[0], top[1], top[2] - objectHeight(id));
    note.error_m = cv::norm(base - centre);
    fields["error_m"] = note.error_m;
    fields["position"] = {base[0], base[1], base[2]};
    fields["seen_at"] = seen->seen_at_s;
  } else {
    fields["error_m"] = nullptr;
    fields["why"] = "the cameras have not seen the object since the drop";
  }
  if (placement_->reported) {
    const cv::Vec3d r = *placement_->reported;
    fields["robot_reported"] = {r[0], r[1], r[2]};
    if (seen && fields.contains("position")) {
      const cv::Vec3d base(fields["position"][0], fields["position"][1], fields["position"][2]);
      fields["robot_vs_cameras_m"] = cv::norm(r - base);
    }
  }
  out.notes.push_back(note);
  s_.log.write("placement", time_s, fields);
  placement_.reset();
}

void RobotStage::endPutDownOnceInView(RobotPart& out, const TrackingPart& tracking, double time_s,
                                      std::int64_t frame) {
  if (!homed_) return;
  if (!clear_view_frame_) {
    // The scene follows the robot's status: once it shows the arm home, two camera frames.
    const auto& status = client_.status();
    if (status && status->last_finished_sequence >= *homed_)
      clear_view_frame_ = frame + 2 * settings_.camera_every + 1;
    return;
  }
  if (frame < *clear_view_frame_) return;
  homed_.reset();
  clear_view_frame_.reset();
  measurePlacement(out, tracking, time_s);
  out.notes.push_back({RobotPart::Note::Kind::PutDownEnded, true, ""});
}

}  // namespace arbci::session
