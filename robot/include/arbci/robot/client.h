// The client the session's cycle uses: never blocks. It binds to one run of the backend (HELLO
// with a fresh nonce, the WELCOME that echoes it, BIND answering the WELCOME's challenge; the
// run's boot id and stop epoch go with every command), and a thread of its own sends heartbeats
// while connected, stamped with their send time on the backend's clock (the offset estimated
// from the WELCOME and the status round trips), so the backend's watchdog halts the arm when this
// process or the link dies or slows. send() queues a command; poll() (once a frame) retransmits
// with back-off until the backend answers, asks for the status five times a second, and turns
// what arrives into events with three honest answers: the command ran (accepted, finished with
// its outcome), did not run (rejected, with the backend's reason, or never sent), or may have run
// (failed with `may_have_run`: the backend restarted or fell silent after it may have received
// the command). A reply from another backend run is only a reason to ask (a fresh HELLO): a
// restart is believed when a WELCOME answering this client's own fresh nonce shows it.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
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
  // Heartbeats sent per watchdog period of the bound backend (at most 200 a second): the
  // watchdog halts only when this many in a row are lost or late, so the rate sets what
  // independent loss a link survives (docs/robot.md). 0: none (a test of the watchdog).
  int heartbeats_per_watchdog = 20;
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
    Connected,  // the handshake with a backend run completed
  } kind;
  std::uint64_t sequence = 0;
  MessageType command = MessageType::Status;
  RejectReason reason = RejectReason::Malformed;
  Outcome outcome = Outcome::Success;
  std::string text;
  // Failed: true when the backend may have received the command and run it (it restarted or went
  // silent before saying); false when it certainly did not run (it was never sent).
  bool may_have_run = false;
};

const char* toString(RobotEvent::Kind kind);

class RobotClient {
 public:
  RobotClient(const Endpoint& backend, const Key& key, const ClientOptions& options = {});
  ~RobotClient();
  RobotClient(const RobotClient&) = delete;
  RobotClient& operator=(const RobotClient&) = delete;

  // Queues a command (GRASP, DROP, HOME, STOP, RESET); returns its sequence number. It goes out
  // once connected, a motion stamped with the stop epoch this client knows then (after a RESET
  // of its own, with the RESET's). After a STOP the backend refuses every motion made before it:
  // the pending ones are still sent until the backend says whether they ran.
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
  // The backend answered a HELLO that its key is not ours (KEY MISMATCH); false once bound.
  bool keyRefused() const { return key_refused_ && !connected_; }
  bool connected() const { return connected_; }
  std::uint64_t sessionId() const { return session_; }
  // The scheduling the heartbeat thread got ("real-time (FIFO 99)", "nice -20", ...; "" before
  // it started), for the session's log.
  std::string heartbeatPriority() const {
    std::lock_guard lock(priority_mutex_);
    return heartbeat_priority_;
  }
  bool busy() const { return !pending_.empty(); }  // commands not yet finished
  // The stop epoch this client's new motion commands carry (0 before the first WELCOME).
  std::uint64_t stopEpoch() const { return epoch_; }
  // The estimated offset of the backend's clock from this one (microseconds), if known.
  std::optional<std::int64_t> clockOffsetUs() const;
  // Whether command `sequence` is known to have been accepted (and so may have moved the arm).
  bool accepted(std::uint64_t sequence) const;

 private:
  struct Pending {
    std::uint64_t sequence = 0;
    MessageType type = MessageType::Home;
    Vec3 target;
    std::optional<std::uint64_t> epoch;  // stamped at the first transmission
    bool transmitted = false;            // it may have reached the backend
    bool accepted = false;
    std::chrono::steady_clock::time_point first_sent, next_send;
    double interval = 0.05;
  };
  // A message of this session with a fresh timestamp and the bound run's boot id.
  Message fresh(MessageType type, std::uint64_t sequence) const;
  void transmit(Pending& p);
  void sendHello();
  void sendBind();
  void sendStatus(std::uint64_t sequence, std::optional<double> clock_s);
  void handle(const Message& m);
  bool welcome(const Message& m);
  void bound(const Message& m);
  void clockSample(std::int64_t sent_us, std::int64_t backend_us);
  void restarted();
  Pending* find(std::uint64_t sequence);
  void complete(std::uint64_t sequence, RobotEvent event);
  void markAccepted(Pending& p);
  void updateAbandonFloor();
  void heartbeatLoop();
  void sendHeartbeat();

  Endpoint backend_;
  Key key_;
  ClientOptions options_;
  UdpSocket socket_;
  std::uint64_t session_;
  bool key_refused_ = false;
  std::atomic<std::uint64_t> next_sequence_{1};
  std::vector<Pending> pending_;
  std::vector<std::uint64_t> accepted_;  // recent accepted sequences (bounded)
  std::vector<RobotEvent> events_;
  std::optional<StatusPayload> status_;
  // Shared with the heartbeat thread.
  std::atomic<std::uint64_t> boot_{0};
  std::atomic<bool> connected_{false};
  std::atomic<std::uint64_t> abandon_below_{1};
  std::atomic<std::int64_t> offset_us_{0};
  std::atomic<bool> offset_known_{false};
  std::atomic<std::int64_t> heartbeat_period_us_{5'000};  // from the bound run's watchdog
  // Heartbeats the heartbeat thread sent since the binding: a motion goes out once it has sent
  // kStreamingHeartbeats (the backend holds one until they come at their rate).
  std::atomic<int> thread_heartbeats_{0};
  bool heartbeatsFlowing() const;
  std::uint64_t epoch_ = 0;
  // HELLOs awaiting their WELCOME: nonce and send time (this clock); the BIND awaiting ACCEPTED.
  std::vector<std::pair<std::uint64_t, std::int64_t>> hellos_;
  std::uint64_t bind_sequence_ = 0, binding_boot_ = 0, bind_challenge_ = 0;
  double bind_interval_ = 0.05;
  std::chrono::steady_clock::time_point bind_started_, next_bind_;
  std::uint32_t watchdog_ms_ = 0;  // the bound run's, for the Connected event
  // STATUS requests awaiting an answer (sequence, send time): clock-offset samples.
  std::vector<std::pair<std::uint64_t, std::int64_t>> status_sent_;
  // Recent offset samples (round trip, offset); the one with the shortest round trip is used.
  std::vector<std::pair<std::int64_t, std::int64_t>> offsets_;
  bool heard_ = false, silent_ = false;
  double hello_interval_ = 0.05;
  std::uint64_t sync_sequence_ = 0;  // the clock request awaited
  bool synced_ = false;
  std::chrono::steady_clock::time_point last_heard_, next_status_, next_hello_, created_;
  std::mutex heartbeat_mutex_;
  std::condition_variable heartbeat_wake_;
  mutable std::mutex priority_mutex_;
  std::string heartbeat_priority_;
  bool stopping_ = false;
  std::thread heartbeat_;
};

}  // namespace arbci::robot
