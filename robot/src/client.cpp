#include "arbci/robot/client.h"

#include <openssl/rand.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace arbci::robot {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

RobotEvent event(RobotEvent::Kind kind, std::string text) {
  return {kind, 0, MessageType::Status, {}, {}, std::move(text)};
}

RobotEvent failure(std::uint64_t sequence, MessageType type, std::string text) {
  return {RobotEvent::Kind::Failed, sequence, type, {}, Outcome::Failed, std::move(text)};
}

}  // namespace

const char* toString(RobotEvent::Kind kind) {
  switch (kind) {
    case RobotEvent::Kind::Accepted:
      return "accepted";
    case RobotEvent::Kind::Rejected:
      return "rejected";
    case RobotEvent::Kind::Finished:
      return "finished";
    case RobotEvent::Kind::Failed:
      return "failed";
    case RobotEvent::Kind::Silent:
      return "silent";
    case RobotEvent::Kind::Reachable:
      return "reachable";
    case RobotEvent::Kind::Restarted:
      return "restarted";
    case RobotEvent::Kind::Connected:
      return "connected";
  }
  return "unknown";
}

RobotClient::RobotClient(const Endpoint& backend, const Key& key, const ClientOptions& options)
    : backend_(backend), key_(key), options_(options), socket_(0, "0.0.0.0") {
  RAND_bytes(reinterpret_cast<unsigned char*>(&session_), sizeof session_);
  created_ = last_heard_ = next_status_ = Clock::now();
  sendHello();
  if (options_.heartbeat_hz > 0.0) heartbeat_ = std::thread([this] { heartbeatLoop(); });
}

RobotClient::~RobotClient() {
  {
    std::lock_guard lock(heartbeat_mutex_);
    stopping_ = true;
  }
  heartbeat_wake_.notify_all();
  if (heartbeat_.joinable()) heartbeat_.join();
}

namespace {
// The heartbeat must not share the fate of a busy machine: the highest priority this process may
// take (real-time FIFO where it may, else the lowest nice value allowed, else as it is). It sleeps
// between beats, so it takes almost nothing from the rest.
std::string raiseThisThread() {
  sched_param param{};
  param.sched_priority = sched_get_priority_max(SCHED_FIFO);
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0)
    return "real-time (FIFO " + std::to_string(param.sched_priority) + ")";
  rlimit limit{};
  int lowest = 0;
  if (getrlimit(RLIMIT_NICE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    lowest = 20 - static_cast<int>(limit.rlim_cur);  // RLIMIT_NICE is 20 - the lowest nice
  for (int nice = -20; nice < 0; ++nice) {
    if (nice < lowest) continue;
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) == 0)
      return "nice " + std::to_string(nice);
  }
  return "normal (the process may not raise a thread's priority)";
}
}  // namespace

// While connected, whatever the cycle is doing: the backend halts a motion when these stop. Shares
// with the cycle only atomics and the socket (a send is one system call).
void RobotClient::heartbeatLoop() {
  {
    const std::string priority = raiseThisThread();
    std::lock_guard lock(priority_mutex_);
    heartbeat_priority_ = priority;
  }
  const auto period = seconds(1.0 / options_.heartbeat_hz);
  std::unique_lock lock(heartbeat_mutex_);
  while (!heartbeat_wake_.wait_for(lock, period, [this] { return stopping_; })) {
    if (!connected_) continue;
    Message m = fresh(MessageType::Heartbeat, next_sequence_++);
    m.abandon_below = abandon_below_;
    socket_.sendTo(encode(m, key_), backend_);
  }
}

Message RobotClient::fresh(MessageType type, std::uint64_t sequence) const {
  Message m;
  m.type = type;
  m.session = session_;
  m.sequence = sequence;
  m.timestamp_ms = wallClockMs();
  m.boot = type == MessageType::Hello ? 0 : boot_.load();  // HELLO asks for the boot id
  return m;
}

void RobotClient::sendHello() {
  socket_.sendTo(encode(fresh(MessageType::Hello, next_sequence_++), key_), backend_);
  next_hello_ = Clock::now() + seconds(hello_interval_);
  hello_interval_ = std::min(hello_interval_ * 2.0, options_.max_retransmit_s);
}

std::uint64_t RobotClient::send(MessageType type, const Vec3& target) {
  if (type == MessageType::Stop) {
    // Nothing sent before a STOP may start after it: the backend refuses it too, however late.
    // (An accepted one is halted by the STOP and finishes "stopped".)
    std::vector<Pending> cancelled;
    for (const Pending& p : pending_) {
      if (isMotion(p.type) && !p.accepted) cancelled.push_back(p);
    }
    for (const Pending& p : cancelled)
      complete(p.sequence, failure(p.sequence, p.type,
                                   std::string(toString(p.type)) + " cancelled: STOP sent"));
  }
  Pending p;
  p.sequence = next_sequence_++;
  p.type = type;
  p.target = target;
  p.first_sent = Clock::now();
  p.interval = options_.first_retransmit_s;
  pending_.push_back(p);
  updateAbandonFloor();
  if (connected_) transmit(pending_.back());
  return p.sequence;
}

void RobotClient::transmit(Pending& p) {
  Message m = fresh(p.type, p.sequence);
  m.target = p.target;
  socket_.sendTo(encode(m, key_), backend_);
  p.next_send = Clock::now() + seconds(p.interval);
  p.interval = std::min(p.interval * 2.0, options_.max_retransmit_s);
}

RobotClient::Pending* RobotClient::find(std::uint64_t sequence) {
  for (Pending& p : pending_) {
    if (p.sequence == sequence) return &p;
  }
  return nullptr;
}

bool RobotClient::accepted(std::uint64_t sequence) const {
  return std::find(accepted_.begin(), accepted_.end(), sequence) != accepted_.end();
}

void RobotClient::complete(std::uint64_t sequence, RobotEvent e) {
  std::erase_if(pending_, [&](const Pending& p) { return p.sequence == sequence; });
  events_.push_back(std::move(e));
  updateAbandonFloor();
}

// Every motion command below the floor is one this client no longer wants: the lowest still
// pending, or (none pending) everything sent so far.
void RobotClient::updateAbandonFloor() {
  std::uint64_t floor = next_sequence_;
  for (const Pending& p : pending_) {
    if (isMotion(p.type)) floor = std::min(floor, p.sequence);
  }
  abandon_below_ = std::max(abandon_below_.load(), floor);
}

void RobotClient::markAccepted(Pending& p) {
  if (p.accepted) return;
  p.accepted = true;
  accepted_.push_back(p.sequence);
  if (accepted_.size() > 64) accepted_.erase(accepted_.begin());
  events_.push_back({RobotEvent::Kind::Accepted, p.sequence, p.type, {}, {}, ""});
  if (p.type == MessageType::Stop || p.type == MessageType::Reset) {
    const char* text = p.type == MessageType::Stop ? "stopped" : "reset";
    complete(p.sequence,
             {RobotEvent::Kind::Finished, p.sequence, p.type, {}, Outcome::Success, text});
  }
}

// The backend run this client was bound to is gone: whatever was pending fails (an accepted
// command died with it; one not yet accepted is never sent to the new run), and the client
// binds to the new run.
void RobotClient::restarted() {
  events_.push_back(event(RobotEvent::Kind::Restarted, "the backend restarted"));
  const std::vector<Pending> lost = pending_;
  for (const Pending& p : lost) {
    const std::string name = toString(p.type);
    complete(p.sequence,
             failure(p.sequence, p.type,
                     p.accepted ? name + " lost: the backend restarted during the command"
                                : name + " not confirmed: the backend restarted before accepting "
                                         "it; it is not sent to the new run"));
  }
  connected_ = false;
  boot_ = 0;
  hello_interval_ = options_.first_retransmit_s;
  sendHello();
}

void RobotClient::handle(const Message& m) {
  if (m.session != session_ || isCommand(m.type)) return;
  const double skew =
      std::abs(static_cast<double>(wallClockMs()) - static_cast<double>(m.timestamp_ms)) / 1000.0;
  if (skew > 30.0) return;  // a stale reply: ignore it
  last_heard_ = Clock::now();
  heard_ = true;
  if (silent_) {
    silent_ = false;
    events_.push_back(event(RobotEvent::Kind::Reachable, "the backend answers again"));
  }
  if (boot_ != 0 && m.boot != boot_) restarted();
  if (m.type == MessageType::Welcome) {
    if (connected_) return;  // a copy of the answer to an earlier HELLO
    boot_ = m.boot;
    connected_ = true;
    events_.push_back(
        event(RobotEvent::Kind::Connected,
              "bound to backend run " + std::to_string(m.boot) +
                  (m.watchdog_ms ? ", watchdog " + std::to_string(m.watchdog_ms) + " ms"
                                 : ", no watchdog")));
    next_status_ = Clock::now();
    for (Pending& p : pending_) transmit(p);
    return;
  }
  if (!connected_ || m.boot != boot_) return;  // from a run this client is not bound to
  Pending* p = find(m.sequence);
  switch (m.type) {
    case MessageType::Accepted:
      if (p) markAccepted(*p);
      break;
    case MessageType::Rejected:
      if (p)
        complete(p->sequence,
                 {RobotEvent::Kind::Rejected, p->sequence, p->type, m.reason, {}, m.text});
      break;
    case MessageType::Finished:
      if (p) {
        const std::uint64_t sequence = p->sequence;
        const MessageType type = p->type;
        markAccepted(*p);  // (a STOP or RESET completes there)
        if (find(sequence))
          complete(sequence, {RobotEvent::Kind::Finished, sequence, type, {}, m.outcome, m.text});
      }
      break;
    case MessageType::StatusReply: {
      status_ = m.status;
      if (sync_sequence_ != 0 && m.sequence == sync_sequence_) synced_ = true;
      // A lost ACCEPTED shows in the status as this session's running command...
      if (m.status.current_is_yours) {
        if (Pending* running = find(m.status.current_sequence)) markAccepted(*running);
      }
      // ...and a lost FINISHED as this session's last finished command.
      if (Pending* done = find(m.status.last_finished_sequence)) {
        const std::uint64_t sequence = done->sequence;
        const MessageType type = done->type;
        markAccepted(*done);
        if (find(sequence))
          complete(sequence, {RobotEvent::Kind::Finished,
                              sequence,
                              type,
                              {},
                              m.status.last_outcome,
                              m.status.last_outcome_text});
      }
      break;
    }
    default:
      break;
  }
}

void RobotClient::poll() {
  for (int i = 0; i < 256; ++i) {
    auto datagram = socket_.receive();
    if (!datagram) break;
    if (!(datagram->from == backend_)) continue;  // only the backend speaks to us
    const Decoded decoded = decode(datagram->bytes.data(), datagram->bytes.size(), key_);
    if (decoded.ok()) handle(decoded.message);
  }
  const auto now = Clock::now();
  // Not bound (or silent, when the backend may have lost our address): HELLO, with back-off.
  if ((!connected_ || silent_) && now >= next_hello_) sendHello();
  std::vector<Pending> expired;
  for (Pending& p : pending_) {
    if (p.accepted) continue;
    if (now - p.first_sent > seconds(options_.give_up_s)) {
      expired.push_back(p);
    } else if (connected_ && now >= p.next_send) {
      transmit(p);
    }
  }
  for (const Pending& p : expired) {
    complete(p.sequence,
             failure(p.sequence, p.type,
                     std::string(toString(p.type)) +
                         " was never accepted: no answer from the backend (given up; it will "
                         "not run later)"));
  }
  if (connected_ && now >= next_status_) {
    next_status_ = now + seconds(options_.status_interval_s);
    socket_.sendTo(encode(fresh(MessageType::Status, next_sequence_++), key_), backend_);
  }
  const auto quiet_since = heard_ ? last_heard_ : created_;
  if (!silent_ && now - quiet_since > seconds(options_.silence_s)) {
    silent_ = true;
    hello_interval_ = options_.max_retransmit_s;
    events_.push_back(event(RobotEvent::Kind::Silent, "no answer from the backend for a second"));
  }
}

bool RobotClient::syncClock(double clock_s, double timeout_s) {
  sync_sequence_ = 0;  // assigned at the first send; resends reuse it (answered from the cache)
  synced_ = false;
  const auto give_up = Clock::now() + seconds(timeout_s);
  auto resend = Clock::now();
  while (!synced_ && Clock::now() < give_up) {
    if (connected_ && Clock::now() >= resend) {
      if (sync_sequence_ == 0) sync_sequence_ = next_sequence_++;
      Message m = fresh(MessageType::Status, sync_sequence_);
      m.clock_s = clock_s;
      socket_.sendTo(encode(m, key_), backend_);
      resend = Clock::now() + seconds(0.05);
    }
    socket_.wait(2);
    poll();
  }
  return synced_;
}

void RobotClient::requestStatus() {
  next_status_ = Clock::now();
}

std::vector<RobotEvent> RobotClient::takeEvents() {
  return std::exchange(events_, {});
}

}  // namespace arbci::robot
