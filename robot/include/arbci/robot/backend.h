// The robot backend: authenticates every datagram, drops replays, runs each command exactly
// once however many copies arrive and only in the backend run (boot) it was sent to, answers
// only the address each session bound at its HELLO, and reports progress and the outcome to the
// client that gave the command. A STOP (or the watchdog, when the commanding client falls
// silent during a motion) latches: motion commands are refused until a RESET.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <ostream>

#include "arbci/robot/protocol.h"
#include "arbci/robot/robot_driver.h"
#include "arbci/robot/settings.h"
#include "arbci/robot/udp_socket.h"

namespace arbci::robot {

struct BackendOptions {
  int port = 0;  // 0: any free port (see RobotBackend::port)
  std::string host = "127.0.0.1";
  double speed_factor = 1.0;  // robot seconds per real second
  // Stepped: the robot moves only when a STATUS carries the requester's clock (to that time; its
  // seconds are robot seconds, speed_factor does not apply), never on the wall clock: a simulated
  // session then gets the same robot, frame for frame, run after run.
  bool stepped = false;
  double status_interval_s = 0.2;  // progress pushed to the commanding client
  double max_clock_skew_s = 30.0;  // older or newer timestamps count as replays
  // While a motion runs, the arm halts (and the stop latches) when no authenticated datagram
  // from the commanding session has arrived for this long; 0 turns it off. A stepped backend
  // needs none: its arm moves only when the client's clock says so.
  double watchdog_s = LinkSettings().watchdog_ms / 1000.0;
  // Asked of the kernel for the socket; it grants at most net.core.rmem_max (times 2).
  int receive_buffer_bytes = 4 << 20;
  // Rejected and ignored datagrams (at most a line per kind a second), and every halt, stop
  // and reset (each once).
  std::ostream* log = nullptr;
};

struct BackendStats {
  std::uint64_t datagrams = 0;
  std::uint64_t ignored = 0;     // undecodable or unauthenticated: no answer
  std::uint64_t replayed = 0;    // authenticated but replayed or stale
  std::uint64_t duplicates = 0;  // retransmissions answered from the cache
  std::uint64_t rejected = 0;    // commands refused (workspace, busy, state)
  std::uint64_t executed = 0;    // motion commands started
  std::uint64_t watchdog_halts = 0;
  std::map<DecodeError, std::uint64_t> by_error;
};

class RobotBackend {
 public:
  RobotBackend(const Key& key, std::unique_ptr<RobotDriver> driver, const BackendOptions& options);
  ~RobotBackend();

  int port() const;
  std::uint64_t boot() const;
  int receiveBufferBytes() const;  // what the kernel granted
  // Handles what has arrived and advances the robot; waits at most `wait_ms` for datagrams.
  void poll(int wait_ms = 5);
  // Polls until `stop` is set.
  void run(const std::atomic<bool>& stop);
  BackendStats stats() const;  // safe from any thread

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arbci::robot
