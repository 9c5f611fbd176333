#include "arbci/robot/backend.h"

#include <openssl/rand.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>

namespace arbci::robot {
namespace {

using SteadyClock = std::chrono::steady_clock;
constexpr std::uint64_t kReplayWindow = 1024;
constexpr size_t kCachedReplies = 256;
constexpr auto kSessionLifetime = std::chrono::minutes(5);

std::uint64_t randomId() {
  std::uint64_t id = 0;
  while (id == 0) RAND_bytes(reinterpret_cast<unsigned char*>(&id), sizeof id);  // 0: "none"
  return id;
}

// True when `sequence` is at least a whole replay window below `highest`, without overflowing
// anywhere in the 64-bit range.
bool belowWindow(std::uint64_t sequence, std::uint64_t highest) {
  return sequence < highest && highest - sequence >= kReplayWindow;
}

}  // namespace

struct RobotBackend::Impl {
  Key key;
  std::unique_ptr<RobotDriver> driver;
  BackendOptions options;
  UdpSocket socket;
  std::uint64_t boot = randomId();

  struct Session {
    Endpoint peer;  // bound at the HELLO: every reply to this session goes there
    std::uint64_t highest = 0;
    std::set<std::uint64_t> seen;              // within the window
    std::map<std::uint64_t, Message> replies;  // cached answers to commands, by sequence
    std::uint64_t last_finished = 0;
    Outcome last_outcome = Outcome::Success;
    std::string last_text;
    // Motion commands below this sequence never start: abandoned by the client (its heartbeat)
    // or sent before a STOP.
    std::uint64_t abandon_below = 0;
    SteadyClock::time_point active;
  };
  std::map<std::uint64_t, Session> sessions;

  struct Running {
    std::uint64_t session = 0, sequence = 0;
    MessageType type = MessageType::Home;
  };
  std::optional<Running> running;
  std::string stop_reason;              // a latched stop: motion commands are refused until a RESET
  std::optional<double> stepped_clock;  // stepped: the clock the robot has reached
  SteadyClock::time_point last_step = SteadyClock::now(), last_push = SteadyClock::now();
  BackendStats stats;
  mutable std::mutex stats_mutex;
  std::map<std::string, SteadyClock::time_point> last_log;

  Impl(const Key& k, std::unique_ptr<RobotDriver> d, const BackendOptions& o)
      : key(k), driver(std::move(d)), options(o), socket(o.port, o.host) {
    if (options.receive_buffer_bytes > 0) socket.setReceiveBuffer(options.receive_buffer_bytes);
  }

  bool watchdogActive() const { return !options.stepped && options.watchdog_s > 0.0; }

  void count(std::uint64_t BackendStats::*field) {
    std::lock_guard lock(stats_mutex);
    ++(stats.*field);
  }

  // What the datagrams did wrong: at most one line per kind a second, so that a flood does not
  // become a flood of log lines.
  void log(const std::string& kind, const std::string& line) {
    if (!options.log) return;
    const auto now = SteadyClock::now();
    auto& last = last_log[kind];
    if (now - last < std::chrono::seconds(1)) return;
    last = now;
    note(line);
  }

  // What the arm did (a halt, a stop, a reset): every one, once, whatever came just before.
  void note(const std::string& line) {
    if (options.log) *options.log << "arbci-robotd: " << line << std::endl;
  }

  void send(const Message& m, const Endpoint& to) {
    Message out = m;
    out.boot = boot;
    out.timestamp_ms = wallClockMs();
    socket.sendTo(encode(out, key), to);
  }

  Message reply(const Message& command, MessageType type) {
    Message m;
    m.type = type;
    m.session = command.session;
    m.sequence = command.sequence;
    return m;
  }

  Message statusFor(std::uint64_t session_id, std::uint64_t sequence) {
    Message m;
    m.type = MessageType::StatusReply;
    m.session = session_id;
    m.sequence = sequence;
    const DriverStatus d = driver->status();
    StatusPayload& s = m.status;
    s.state = stop_reason.empty() ? d.state : RobotState::Stopped;
    s.stop_reason = stop_reason;
    s.tool = d.tool;
    s.gripper_opening = d.gripper_opening;
    s.holding = d.holding;
    s.progress = d.progress;
    if (running) {
      s.current_command = running->type;
      s.current_sequence = running->sequence;
      s.current_is_yours = running->session == session_id;
    }
    const auto found = sessions.find(session_id);
    if (found != sessions.end()) {
      s.last_finished_sequence = found->second.last_finished;
      s.last_outcome = found->second.last_outcome;
      s.last_outcome_text = found->second.last_text;
    }
    s.objects = driver->world();
    return m;
  }

  void finish(Outcome outcome, const std::string& text) {
    if (!running) return;
    const auto found = sessions.find(running->session);
    if (found != sessions.end()) {
      Session& s = found->second;
      s.last_finished = running->sequence;
      s.last_outcome = outcome;
      s.last_text = text;
      Message m;
      m.type = MessageType::Finished;
      m.session = running->session;
      m.sequence = running->sequence;
      m.outcome = outcome;
      m.text = text;
      s.replies[running->sequence] = m;  // a retransmitted command now gets its outcome
      send(m, s.peer);
    }
    running.reset();
  }

  // Halts the arm at once; motion commands are refused until a RESET.
  void latchStop(const std::string& reason, const std::string& outcome_text) {
    const bool halted = running.has_value();
    const std::string what = halted ? toString(running->type) + std::string(" halted") : "";
    driver->stop();
    finish(Outcome::Stopped, outcome_text);
    const bool latched = stop_reason.empty();
    if (latched) stop_reason = reason;
    if (halted || latched) {
      note("stopped: " + reason + (halted ? " (" + what + ")" : "") +
           "; motion commands refused until RESET");
    } else {
      log("stop again", "stopped again: " + reason + " (already stopped: " + stop_reason + ")");
    }
  }

  void handle(const Datagram& d) {
    count(&BackendStats::datagrams);
    const Decoded decoded = decode(d.bytes.data(), d.bytes.size(), key);
    if (!decoded.ok()) {
      {
        std::lock_guard lock(stats_mutex);
        ++stats.ignored;
        ++stats.by_error[decoded.error];
      }
      log(toString(decoded.error),
          "ignored a datagram from " + d.from.toString() + ": " + toString(decoded.error));
      return;
    }
    const Message& m = decoded.message;
    if (!isCommand(m.type)) {
      count(&BackendStats::ignored);
      return;  // a reply sent to the backend: nothing to do
    }
    const double skew =
        std::abs(static_cast<double>(wallClockMs()) - static_cast<double>(m.timestamp_ms)) / 1000.0;
    if (skew > options.max_clock_skew_s) {
      reject(m, d.from, RejectReason::Replayed,
             "timestamp " + std::to_string(static_cast<long>(skew)) +
                 " s away from the backend's clock");
      return;
    }
    const auto found = sessions.find(m.session);
    if (m.type == MessageType::Hello) {
      hello(m, d.from);
      return;
    }
    if (m.boot != boot) {
      // Sent to another run of the backend (a capture replayed after a restart, or a client
      // that has not noticed the restart yet): never run; the client learns it must HELLO.
      reject(m, found != sessions.end() ? found->second.peer : d.from, RejectReason::UnknownBoot,
             "sent to backend run " + std::to_string(m.boot) + ", this is run " +
                 std::to_string(boot) + ": the backend restarted; say HELLO again");
      return;
    }
    if (found == sessions.end()) {
      reject(m, d.from, RejectReason::NotAuthenticated, "no HELLO from this session in this run");
      return;
    }
    Session& s = found->second;
    if (belowWindow(m.sequence, s.highest)) {
      reject(m, s.peer, RejectReason::Replayed,
             "sequence " + std::to_string(m.sequence) + " is older than the replay window");
      return;
    }
    if (s.seen.count(m.sequence)) {
      const auto cached = s.replies.find(m.sequence);
      if (cached != s.replies.end()) {
        count(&BackendStats::duplicates);
        send(cached->second, s.peer);
      } else if (m.type == MessageType::Status) {
        send(statusFor(m.session, m.sequence), s.peer);
      } else if (m.type != MessageType::Heartbeat) {
        reject(m, s.peer, RejectReason::Replayed,
               "sequence " + std::to_string(m.sequence) + " was already used");
      }
      return;
    }
    s.seen.insert(m.sequence);
    s.highest = std::max(s.highest, m.sequence);
    while (!s.seen.empty() && belowWindow(*s.seen.begin(), s.highest)) s.seen.erase(s.seen.begin());
    s.active = SteadyClock::now();  // fresh and authenticated: feeds the watchdog
    process(m, s);
    while (s.replies.size() > kCachedReplies) s.replies.erase(s.replies.begin());
  }

  // HELLO binds the session to this run and to the sender's address. Only a HELLO newer than
  // anything the session sent this run does so: a replayed one cannot redirect the replies.
  void hello(const Message& m, const Endpoint& from) {
    const auto found = sessions.find(m.session);
    if (found != sessions.end() && m.sequence <= found->second.highest) {
      reject(m, found->second.peer, RejectReason::Replayed,
             "HELLO " + std::to_string(m.sequence) + " is not newer than the session's last");
      return;
    }
    Session& s = sessions[m.session];
    s.peer = from;
    s.highest = m.sequence;
    s.seen.insert(m.sequence);
    s.active = SteadyClock::now();
    Message welcome = reply(m, MessageType::Welcome);
    welcome.watchdog_ms =
        watchdogActive() ? static_cast<std::uint32_t>(std::lround(options.watchdog_s * 1000)) : 0;
    send(welcome, from);
  }

  void reject(const Message& m, const Endpoint& to, RejectReason reason, const std::string& text) {
    Message r = reply(m, MessageType::Rejected);
    r.reason = reason;
    r.text = text;
    const bool stale = reason == RejectReason::Replayed || reason == RejectReason::UnknownBoot;
    count(stale ? &BackendStats::replayed : &BackendStats::rejected);
    log(toString(reason),
        std::string("rejected ") + toString(m.type) + " from " + to.toString() + ": " + text);
    const auto found = sessions.find(m.session);
    if (found != sessions.end() && !stale) found->second.replies[m.sequence] = r;
    send(r, to);
  }

  void accept(const Message& m, Session& s) {
    const Message accepted = reply(m, MessageType::Accepted);
    s.replies[m.sequence] = accepted;
    send(accepted, s.peer);
  }

  void process(const Message& m, Session& s) {
    switch (m.type) {
      case MessageType::Status:
        if (options.stepped && m.clock_s) stepTo(*m.clock_s);
        send(statusFor(m.session, m.sequence), s.peer);
        return;
      case MessageType::Heartbeat:
        s.abandon_below = std::max(s.abandon_below, m.abandon_below);
        if (running && running->session == m.session && running->sequence < s.abandon_below)
          latchStop("halted: the client gave up on the command",
                    "halted: the client gave up on the command");
        return;
      case MessageType::Stop: {
        latchStop("emergency stop", "stopped by STOP");
        // Everything sent before the STOP stays unrun, however late it arrives (and after a
        // RESET too): this session's by sequence, other sessions' up to what they had sent.
        for (auto& [id, other] : sessions) {
          if (id != m.session)
            other.abandon_below =
                std::max(other.abandon_below, other.highest + (other.highest < UINT64_MAX));
        }
        s.abandon_below = std::max(s.abandon_below, m.sequence);
        accept(m, s);
        return;
      }
      case MessageType::Reset:
        if (!stop_reason.empty()) note("RESET: the stop (" + stop_reason + ") is lifted");
        stop_reason.clear();
        accept(m, s);
        return;
      default: {
        if (!isMotion(m.type)) return;
        if (!stop_reason.empty()) {
          reject(m, s.peer, RejectReason::Stopped,
                 "the robot is stopped (" + stop_reason + "): RESET first");
          return;
        }
        if (m.sequence < s.abandon_below) {
          reject(m, s.peer, RejectReason::Cancelled,
                 "sequence " + std::to_string(m.sequence) +
                     " was given up by the client or sent before a STOP");
          return;
        }
        if (running) {
          reject(m, s.peer, RejectReason::Busy,
                 std::string("busy with ") + toString(running->type) + " " +
                     std::to_string(running->sequence));
          return;
        }
        const DriverCommand command{m.type, m.target};
        if (const auto refusal = driver->check(command)) {
          reject(m, s.peer, refusal->reason, refusal->text);
          return;
        }
        driver->start(command);
        running = Running{m.session, m.sequence, m.type};
        count(&BackendStats::executed);
        accept(m, s);
        if (m.type != MessageType::Home) {
          // The robot's own record of where it went (a session's summary is checked against it).
          char target[96];
          std::snprintf(target, sizeof target, "(%.4f, %.4f, %.4f)", m.target.x, m.target.y,
                        m.target.z);
          note(std::string("ran ") + toString(m.type) + " " + std::to_string(m.sequence) + " at " +
               target);
        }
        last_push = SteadyClock::now();
      }
    }
  }

  // Stepped: the robot's time follows the requester's clock.
  void stepTo(double clock_s) {
    if (stepped_clock && clock_s > *stepped_clock && running) {
      double remaining = clock_s - *stepped_clock;  // robot seconds are clock seconds
      // In the wall-clock loop's steps (at most 0.1 s), so both move the arm alike.
      while (running && remaining > 1e-12) {
        const double dt = std::min(remaining, 0.1);
        remaining -= dt;
        if (const auto result = driver->step(dt)) finish(result->outcome, result->text);
      }
    }
    if (!stepped_clock || clock_s > *stepped_clock) stepped_clock = clock_s;
  }

  // When the watchdog must next look (nothing when no motion runs).
  std::optional<SteadyClock::time_point> watchdogDeadline() const {
    if (!running || !watchdogActive()) return std::nullopt;
    const auto found = sessions.find(running->session);
    if (found == sessions.end()) return SteadyClock::now();
    return found->second.active + std::chrono::duration_cast<SteadyClock::duration>(
                                      std::chrono::duration<double>(options.watchdog_s));
  }

  void advance() {
    const auto now = SteadyClock::now();
    if (const auto deadline = watchdogDeadline(); deadline && now >= *deadline) {
      latchStop("halted: link lost", "halted: link lost (no heartbeat from the client)");
      count(&BackendStats::watchdog_halts);
    }
    const double elapsed = std::chrono::duration<double>(now - last_step).count();
    last_step = now;
    if (running && !options.stepped) {
      if (const auto result = driver->step(std::min(elapsed, 0.1) * options.speed_factor))
        finish(result->outcome, result->text);
    }
    if (running &&
        std::chrono::duration<double>(now - last_push).count() >= options.status_interval_s) {
      last_push = now;
      const auto found = sessions.find(running->session);
      if (found != sessions.end()) send(statusFor(running->session, 0), found->second.peer);
    }
    std::erase_if(sessions, [&](const auto& entry) {
      return now - entry.second.active > kSessionLifetime &&
             !(running && running->session == entry.first);
    });
  }
};

RobotBackend::RobotBackend(const Key& key, std::unique_ptr<RobotDriver> driver,
                           const BackendOptions& options)
    : impl_(std::make_unique<Impl>(key, std::move(driver), options)) {}

RobotBackend::~RobotBackend() = default;

int RobotBackend::port() const {
  return impl_->socket.port();
}
std::uint64_t RobotBackend::boot() const {
  return impl_->boot;
}
int RobotBackend::receiveBufferBytes() const {
  return impl_->socket.receiveBuffer();
}

void RobotBackend::poll(int wait_ms) {
  Impl& m = *impl_;
  // Never sleep past the watchdog's deadline: the halt comes on time, not a poll later.
  auto wait = std::chrono::microseconds(wait_ms * 1000LL);
  if (const auto deadline = m.watchdogDeadline()) {
    wait = std::clamp(std::chrono::ceil<std::chrono::microseconds>(*deadline - SteadyClock::now()),
                      std::chrono::microseconds(0), wait);
  }
  m.socket.wait(wait);
  for (int i = 0; i < 256; ++i) {  // bounded, so a flood cannot starve the arm
    auto datagram = m.socket.receive();
    if (!datagram) break;
    m.handle(*datagram);
  }
  m.advance();
}

void RobotBackend::run(const std::atomic<bool>& stop) {
  while (!stop.load()) poll(5);
}

BackendStats RobotBackend::stats() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace arbci::robot
