#include "arbci/robot/backend.h"

#include <openssl/rand.h>

#include <chrono>
#include <cmath>
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
  RAND_bytes(reinterpret_cast<unsigned char*>(&id), sizeof id);
  return id;
}

}  // namespace

struct RobotBackend::Impl {
  Key key;
  std::unique_ptr<RobotDriver> driver;
  BackendOptions options;
  UdpSocket socket;
  std::uint64_t boot = randomId();

  struct Session {
    Endpoint peer;
    std::uint64_t highest = 0;
    std::set<std::uint64_t> seen;              // within the window
    std::map<std::uint64_t, Message> replies;  // cached answers to commands, by sequence
    std::uint64_t last_finished = 0;
    Outcome last_outcome = Outcome::Success;
    std::string last_text;
    SteadyClock::time_point active;
  };
  std::map<std::uint64_t, Session> sessions;

  struct Running {
    std::uint64_t session = 0, sequence = 0;
    MessageType type = MessageType::Home;
  };
  std::optional<Running> running;
  std::optional<double> stepped_clock;  // stepped: the clock the robot has reached
  SteadyClock::time_point last_step = SteadyClock::now(), last_push = SteadyClock::now();
  BackendStats stats;
  mutable std::mutex stats_mutex;
  std::map<std::string, SteadyClock::time_point> last_log;

  Impl(const Key& k, std::unique_ptr<RobotDriver> d, const BackendOptions& o)
      : key(k), driver(std::move(d)), options(o), socket(o.port, o.host) {}

  void log(const std::string& kind, const std::string& line) {
    if (!options.log) return;
    // At most one line per kind a second: a flood must not become a flood of log lines.
    const auto now = SteadyClock::now();
    auto& last = last_log[kind];
    if (now - last < std::chrono::seconds(1)) return;
    last = now;
    *options.log << "arbci-robotd: " << line << std::endl;
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
    s.state = d.state;
    s.tool = d.tool;
    s.gripper_opening = d.gripper_opening;
    s.holding = d.holding;
    s.progress = d.progress;
    if (running) {
      s.current_command = running->type;
      s.current_sequence = running->sequence;
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

  void handle(const Datagram& d) {
    {
      std::lock_guard lock(stats_mutex);
      ++stats.datagrams;
    }
    const Decoded decoded = decode(d.bytes.data(), d.bytes.size(), key);
    if (!decoded.ok()) {
      std::lock_guard lock(stats_mutex);
      ++stats.ignored;
      ++stats.by_error[decoded.error];
      log(toString(decoded.error),
          "ignored a datagram from " + d.from.toString() + ": " + toString(decoded.error));
      return;
    }
    const Message& m = decoded.message;
    if (!isCommand(m.type)) {
      std::lock_guard lock(stats_mutex);
      ++stats.ignored;
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
    Session& s = sessions[m.session];
    s.peer = d.from;  // answers go to the sender, and so do this session's progress and outcomes
    s.active = SteadyClock::now();
    if (s.highest > kReplayWindow && m.sequence <= s.highest - kReplayWindow) {
      reject(m, d.from, RejectReason::Replayed,
             "sequence " + std::to_string(m.sequence) + " is older than the replay window");
      return;
    }
    if (s.seen.count(m.sequence)) {
      const auto cached = s.replies.find(m.sequence);
      if (cached != s.replies.end()) {
        std::lock_guard lock(stats_mutex);
        ++stats.duplicates;
        send(cached->second, d.from);
      } else if (m.type == MessageType::Status) {
        send(statusFor(m.session, m.sequence), d.from);
      } else {
        reject(m, d.from, RejectReason::Replayed,
               "sequence " + std::to_string(m.sequence) + " was already used");
      }
      return;
    }
    s.seen.insert(m.sequence);
    s.highest = std::max(s.highest, m.sequence);
    while (!s.seen.empty() && *s.seen.begin() + kReplayWindow < s.highest)
      s.seen.erase(s.seen.begin());
    process(m, s, d.from);
    while (s.replies.size() > kCachedReplies) s.replies.erase(s.replies.begin());
  }

  void reject(const Message& m, const Endpoint& to, RejectReason reason, const std::string& text) {
    Message r = reply(m, MessageType::Rejected);
    r.reason = reason;
    r.text = text;
    {
      std::lock_guard lock(stats_mutex);
      if (reason == RejectReason::Replayed)
        ++stats.replayed;
      else
        ++stats.rejected;
    }
    log(toString(reason),
        std::string("rejected ") + toString(m.type) + " from " + to.toString() + ": " + text);
    const auto found = sessions.find(m.session);
    if (found != sessions.end() && reason != RejectReason::Replayed)
      found->second.replies[m.sequence] = r;
    send(r, to);
  }

  void process(const Message& m, Session& s, const Endpoint& from) {
    switch (m.type) {
      case MessageType::Status:
        if (options.stepped && m.clock_s) stepTo(*m.clock_s);
        send(statusFor(m.session, m.sequence), from);
        return;
      case MessageType::Stop: {
        driver->stop();
        finish(Outcome::Stopped, "stopped by STOP");
        const Message accepted = reply(m, MessageType::Accepted);
        s.replies[m.sequence] = accepted;
        send(accepted, from);
        return;
      }
      default: {
        if (running) {
          reject(m, from, RejectReason::Busy,
                 std::string("busy with ") + toString(running->type) + " " +
                     std::to_string(running->sequence));
          return;
        }
        const DriverCommand command{m.type, m.target};
        if (const auto refusal = driver->check(command)) {
          reject(m, from, refusal->reason, refusal->text);
          return;
        }
        driver->start(command);
        running = Running{m.session, m.sequence, m.type};
        {
          std::lock_guard lock(stats_mutex);
          ++stats.executed;
        }
        const Message accepted = reply(m, MessageType::Accepted);
        s.replies[m.sequence] = accepted;
        send(accepted, from);
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

  void advance() {
    const auto now = SteadyClock::now();
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

void RobotBackend::poll(int wait_ms) {
  Impl& m = *impl_;
  m.socket.wait(wait_ms);
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
