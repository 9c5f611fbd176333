// The robot's part of each trial, on the session's cycle: grasp the selected object where the
// cameras last saw it; put it on the selected cell, or back where it came from; send the arm home
// so the cameras see the table again; measure where the object landed. And the experimenter's
// recovery commands (reset, home, open the gripper). It owns the link to the backend (and the
// simulated backend's process), acts on the robot requests of the record in the order posted,
// logs every command and event, and tells the paradigm on the record how the trial's robot step
// went. A stepped backend (a reproducible simulation) is moved to the session's clock while the
// robot has anything to do.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "arbci/session/robot_connection.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct RobotStageSettings {
  WorldSettings world;   // the table's height, the objects' heights, the grid
  int camera_every = 1;  // display frames per camera frame
};

class RobotStage final : public Stage {
 public:
  RobotStage(const RobotStageSettings& settings, RobotLink link, const StageServices& services);
  const char* name() const override { return "robot"; }
  void step(Cycle& cycle) override;
  // The run ends (a fault, an abort, a full disk): a motion still in flight is STOPped, so the
  // arm never runs on unsupervised (the watchdog would halt it too, once heartbeats stop).
  void stop(Cycle& cycle, const std::string& reason) override;
  // STOP now, not a frame later (the experimenter's emergency stop); the paradigm is told on the
  // record next cycle.
  void stopNow(double time_s);

 private:
  void act(const Request& request, Cycle& cycle);
  void send(robot::MessageType type, const cv::Vec3d& target, double time_s);
  void grasp(const GraspRequest& request, RobotPart& out);
  // "" when the grasp may go, else why not (noted on the record as the robot's answer).
  std::string whyNotGrasp(const GraspRequest& request) const;
  void drop(const DropRequest& request);
  void stop(double time_s);
  void reset(double time_s);
  void resetIfLatched(double time_s);
  void home(double time_s);
  void release(double time_s);
  void finishPutDown(double time_s);
  void sendRecovery(robot::MessageType type, const cv::Vec3d& target, const char* what,
                    double time_s);
  void handleRecoveryEvent(const robot::RobotEvent& e, RobotPart& out, double time_s);
  void handleEvents(RobotPart& out, double time_s);
  double objectHeight(int id) const;
  void noteReportedPlacement(double time_s);
  void measurePlacement(RobotPart& out, const TrackingPart& tracking, double time_s);
  void endPutDownOnceInView(RobotPart& out, const TrackingPart& tracking, double time_s,
                            std::int64_t frame);
  bool busy() const { return command_.has_value() || recovery_.has_value(); }
  std::optional<int> holding() const;
  std::string whyNotMove() const;
  std::string whyNotRelease() const;

  RobotStageSettings settings_;
  StageServices s_;
  RobotLink link_;
  robot::RobotClient& client_;
  bool stepped_;  // false once a stepped backend stops answering (the client reports it silent)
  std::vector<std::string> messages_;  // for the Robot panel: the last 200
  std::shared_ptr<const std::vector<std::string>> published_;
  std::uint64_t messages_added_ = 0, messages_published_ = 0;
  std::optional<std::uint64_t> command_;  // the trial's command in flight
  robot::MessageType command_type_ = robot::MessageType::Home;
  std::optional<int> grasped_id_;
  cv::Vec3d grasped_from_;  // where the object in the gripper was taken from
  bool giving_back_ = false;
  // A placement to measure: the cameras' view of the object once the arm has left the table
  // (the robot's own report of where it let go is logged beside it, not used as the result).
  struct Placement {
    int trial = 0;
    std::pair<int, int> cell;
    std::uint64_t command = 0;
    double since_s = 0.0;
    std::optional<cv::Vec3d> reported;  // the object's base as the robot's status has it
  };
  std::optional<Placement> placement_;
  std::optional<DropRequest> drop_;  // the put-down in progress
  // The arm is home after a put-down (that command), and the frame from which the cameras have
  // seen the table without it.
  std::optional<std::uint64_t> homed_;
  std::optional<std::int64_t> clear_view_frame_;
  bool at_home_ = true;
  // The experimenter's recovery command in flight: its sequence and what it is.
  std::optional<std::uint64_t> recovery_;
  robot::MessageType recovery_type_ = robot::MessageType::Home;
  bool stopped_ = false;  // a STOP went out and no command since
  bool answered_ = false;
};

}  // namespace arbci::session
