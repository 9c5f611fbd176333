// The robot's part of each trial, on the session's cycle: grasp the selected object where the
// cameras last saw it; put it on the selected cell, or back where it came from when the cell is
// taken; send the arm home so the cameras see the table again; measure where the object landed.
// It owns the robot client, logs every command and event (log.jsonl and the Robot panel's
// messages), and tells the session through its hooks when the paradigm may go on. A stepped
// backend (a reproducible simulation) is moved to the session's clock while the robot has
// anything to do.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/matx.hpp>

#include "arbci/render/hmd_view.h"
#include "arbci/robot/client.h"
#include "session/session_config.h"
#include "session/session_log.h"
#include "session/stage.h"
#include "session/trial_record.h"

namespace arbci::app {

class RobotChoreography final : public Stage {
 public:
  struct Hooks {
    std::function<TrialRecord&()> current_trial;
    std::function<TrialRecord&(int trial)> trial;  // by its number (from 1)
    // The robot's step of the trial ended: the paradigm goes on (or waits in a fault).
    std::function<void(bool success, const std::string& why)> finished;
    std::function<void(int object_id)> object_moved;  // the cameras must see it anew
    std::function<void()> put_down_ended;  // home, and the cameras have seen the table since
  };
  RobotChoreography(std::unique_ptr<robot::RobotClient> client, bool stepped, SessionLog& log,
                    const WorldSettings& world, const render::GridLayout& grid, int camera_every,
                    Hooks hooks);

  const char* name() const override { return "robot"; }
  // Each frame, before the paradigm: the robot brought up to the cycle's time, its events
  // handled, a finished placement measured.
  void step(CycleContext& cycle) override;
  void grasp(int object_id, const cv::Vec3d& at, double time_s);
  // Onto `cell`, or (`give_back`) back where the object was grasped.
  void drop(std::pair<int, int> cell, bool give_back, double time_s);
  // STOP (the paradigm's, an emergency stop among them): the client cancels what is pending.
  void stop(double time_s);
  // The experimenter's recovery after a stop or a fault (outside any trial's command): RESET
  // lifts a latched stop; HOME parks the arm; release puts what the gripper holds back where it
  // was taken from, then parks the arm. Motions lift a latched stop first.
  void reset(double time_s);
  void home(double time_s);
  void release(double time_s);
  // RESET when a stop is latched (the experimenter goes on: motions must run again).
  void resetIfLatched(double time_s);
  // A put-down interrupted after the object was let go: the arm goes home and the put-down ends
  // as usual (once the cameras have seen the table).
  void finishPutDown(double time_s);
  // Why an experimenter's motion cannot go now ("" when it can): a command running, the backend
  // silent or not yet heard.
  std::string whyNotMove() const;
  // Why release cannot go now: as whyNotMove(), or the gripper empty, or the place unknown.
  std::string whyNotRelease() const;

  // A placement still to be measured (at most 3 s after the drop).
  bool measuring(double time_s) const;
  std::optional<int> grasped() const { return grasped_id_; }
  // What the backend last said the gripper holds (its marker id), if anything.
  std::optional<int> holding() const;
  // The arm is parked: HOME finished since the last motion (it starts home).
  bool atHome() const { return at_home_; }
  // A command of the trial's or the experimenter's is running.
  bool busy() const { return command_.has_value() || recovery_.has_value(); }
  const std::optional<robot::StatusPayload>& status() const { return client_->status(); }
  bool silent() const { return client_->silent(); }
  // The backend answers STATUS: a stepped one is asked now, at `time_s` (reproducibly); one on
  // the wall clock has sent a status and is not silent.
  bool answersStatus(double time_s);
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  void send(robot::MessageType type, const cv::Vec3d& target, double time_s);
  void sendRecovery(robot::MessageType type, const cv::Vec3d& target, const char* what,
                    double time_s);
  void handleRecoveryEvent(const robot::RobotEvent& e, double time_s);
  void handleEvents(double time_s);
  void measurePlacement(double time_s);
  void endPutDownOnceInView(std::int64_t frame);

  std::unique_ptr<robot::RobotClient> client_;
  bool stepped_;  // false once a stepped backend stops answering (the client reports it silent)
  SessionLog& log_;
  const WorldSettings& world_;
  render::GridLayout grid_;
  int camera_every_;
  Hooks hooks_;
  std::vector<std::string> messages_;
  std::optional<std::uint64_t> command_;  // the trial's command in flight
  robot::MessageType command_type_ = robot::MessageType::Home;
  std::optional<int> grasped_id_;
  cv::Vec3d grasped_from_;  // where the object in the gripper was taken from
  bool giving_back_ = false;
  // A placement to measure once the robot reports the world after the drop: (trial, command).
  std::optional<std::pair<int, std::uint64_t>> placement_;
  double placement_since_ = 0.0;
  // The arm is home after a put-down (that command), and the frame from which the cameras have
  // seen the table without it.
  std::optional<std::uint64_t> homed_;
  std::optional<std::int64_t> clear_view_frame_;
  bool at_home_ = true;
  // The experimenter's recovery command in flight: its sequence and what it is.
  std::optional<std::uint64_t> recovery_;
  robot::MessageType recovery_type_ = robot::MessageType::Home;
};

}  // namespace arbci::app
