// The client the session's cycle uses: never blocks. send() queues a command; poll() (once a
// frame) retransmits with back-off until the backend accepts, asks for the status five times a
// second, and turns what arrives into events: accepted, rejected (with the reason), finished
// (with the outcome), and failures the backend cannot report itself: silence for a second, a
// restart during a command (never taken for success), no answer at all.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arbci/robot/protocol.h"
#include "arbci/robot/udp_socket.h"

namespace arbci::robot {

struct ClientOptions {
  double first_retransmit_s = 0.05;
  double max_retransmit_s = 0.4;
  double status_interval_s = 0.2;
  double silence_s = 1.0;   // no answer for this long: the backend is reported silent
  double give_up_s = 15.0;  // a command nobody accepted in this long fails
};

struct RobotEvent {
  enum class Kind {
    Accepted,
    Rejected,   // reason, text
    Finished,   // outcome, text
    Failed,     // the command's fate is unknown or it was lost: text says why
    Silent,     // no answer for `silence_s`
    Reachable,  // answers again after silence
    Restarted,  // the backend's boot id changed
  } kind;
  std::uint64_t sequence = 0;
  MessageType command = MessageType::Status;
  RejectReason reason = RejectReason::Malformed;
  Outcome outcome = Outcome::Success;
  std::string text;
};

const char* toString(RobotEvent::Kind kind);

class RobotClient {
 public:
  RobotClient(const Endpoint& backend, const Key& key, const ClientOptions& options = {});
  ~RobotClient();
  RobotClient(const RobotClient&) = delete;
  RobotClient& operator=(const RobotClient&) = delete;

  // Queues a command (GRASP, DROP, HOME, STOP); returns its sequence number.
  std::uint64_t send(MessageType type, const Vec3& target = {});
  void poll();
  // The next poll() asks for a status at once rather than at the status interval (the session
  // wants to see the world right after a command finished).
  void requestStatus();
  // For a stepped backend (a reproducible simulation): asks for a status at `clock_s` of the
  // session's clock, so the robot moves to that time, and waits for the answer (at most
  // `timeout_s`, resending every 50 ms). Events and status are up to that instant on return.
  // False if no answer came.
  bool syncClock(double clock_s, double timeout_s = 2.0);
  std::vector<RobotEvent> takeEvents();
  // The latest status the backend sent (state, tool, gripper, world).
  const std::optional<StatusPayload>& status() const { return status_; }
  bool silent() const { return silent_; }
  bool busy() const { return !pending_.empty(); }  // commands not yet finished

 private:
  struct Pending {
    std::uint64_t sequence = 0;
    MessageType type = MessageType::Home;
    Vec3 target;
    bool accepted = false;
    std::uint64_t accepted_boot = 0;
    std::chrono::steady_clock::time_point first_sent, next_send;
    double interval = 0.05;
  };
  void transmit(Pending& p);
  void handle(const Message& m);
  Pending* find(std::uint64_t sequence);
  void complete(std::uint64_t sequence, RobotEvent event);

  Endpoint backend_;
  Key key_;
  ClientOptions options_;
  UdpSocket socket_;
  std::uint64_t session_;
  std::uint64_t next_sequence_ = 1;
  std::vector<Pending> pending_;
  std::vector<RobotEvent> events_;
  std::optional<StatusPayload> status_;
  std::uint64_t boot_ = 0;
  bool heard_ = false, silent_ = false;
  std::uint64_t sync_sequence_ = 0;  // the clock request awaited
  bool synced_ = false;
  std::chrono::steady_clock::time_point last_heard_, next_status_, created_;
};

}  // namespace arbci::robot
