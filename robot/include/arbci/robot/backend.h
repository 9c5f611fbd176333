// The robot backend: authenticates every datagram, drops replays, runs each command exactly
// once however many copies arrive and only in the backend run (boot) and stop epoch it was made
// for, binds a session to an address only through a fresh challenge, answers only that address,
// and reports progress and the outcome to the client that gave the command. A STOP (or the
// watchdog, when the commanding client's heartbeats stop arriving fresh during a motion)
// latches: motion commands are refused until a RESET, and commands made before it never run.
// A flood costs little: datagrams from the bound address of a known session are verified and
// handled first; everything else is sorted by its header and verified only within a budget of
// its source address's. A motion waits for its session's first fresh heartbeat.
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
  std::string host = LinkSettings().host;
  double speed_factor = 1.0;  // robot seconds per real second
  // Stepped: the robot moves only when a STATUS carries the requester's clock (to that time; its
  // seconds are robot seconds, speed_factor does not apply), never on the wall clock: a simulated
  // session then gets the same robot, frame for frame, run after run.
  bool stepped = false;
  double status_interval_s = 0.2;  // progress pushed to the commanding client
  double max_clock_skew_s = 30.0;  // older or newer timestamps count as replays
  // While a motion runs, the arm halts (and the stop latches) this long after the later of the
  // motion's start and the send time of the commanding session's newest heartbeat (on this
  // backend's clock): a delayed link halts as a dead one does. 0 turns it off. A stepped backend
  // needs none: its arm moves only when the client's clock says so.
  double watchdog_s = LinkSettings().watchdog_ms / 1000.0;
  // With the watchdog on, a motion from a session that has sent no heartbeat yet is held until
  // the first one arrives (started if it arrives fresh, refused `unreachable` if stale) and
  // refused after this long without one: until then nothing shows the watchdog could halt it.
  double first_heartbeat_wait_s = 1.0;
  // Asked of the kernel for the socket (it grants at most net.core.rmem_max, times 2). Sized for
  // latency, not throughput: a flood that outruns the backend is dropped by the kernel rather
  // than queued in front of a STOP (256 KiB hold about 110 full-size datagrams).
  int receive_buffer_bytes = 256 << 10;
  // Datagrams not from a bound session's address (HELLO, BIND, strays, forgeries) are verified
  // at most this many a second from each source address (a flood from one address never spends
  // another's budget); the rest are dropped unread. Bound sessions are never limited.
  double unbound_per_s = 200.0;
  // Refusals sent to an address that is not a bound session's (a stale or unknown command), at
  // most this many a second, and only when smaller than the datagram refused.
  double refusals_per_s = 10.0;
  // run() raises its thread to the priority a motion controller should have, where permitted.
  bool raise_priority = false;
  // Rejected and ignored datagrams (at most a line per kind a second), and every halt, stop
  // and reset (each once).
  std::ostream* log = nullptr;
};

struct BackendStats {
  std::uint64_t datagrams = 0;
  std::uint64_t ignored = 0;  // undecodable or unauthenticated: no answer
  std::uint64_t shed = 0;     // dropped unread: unknown session, or over the unbound budget
  std::uint64_t stale_heartbeats = 0;  // sent longer ago than the watchdog: fed nothing
  std::uint64_t replayed = 0;          // authenticated but replayed or stale
  std::uint64_t duplicates = 0;        // retransmissions answered from the cache
  std::uint64_t rejected = 0;          // commands refused (workspace, busy, state)
  std::uint64_t executed = 0;          // motion commands started
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
  // The scheduling run() got ("" before it ran, or when not asked to raise it).
  std::string priority() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arbci::robot
