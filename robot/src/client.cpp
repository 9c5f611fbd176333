#include "arbci/robot/client.h"

#include <openssl/rand.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "arbci/robot/thread_priority.h"

namespace arbci::robot {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

RobotEvent event(RobotEvent::Kind kind, std::string text) {
  return {kind, 0, MessageType::Status, {}, {}, std::move(text)};
}

RobotEvent failure(std::uint64_t sequence, MessageType type, std::string text, bool may_have_run) {
  return {RobotEvent::Kind::Failed, sequence,        type,        {},
          Outcome::Failed,          std::move(text), may_have_run};
}

std::uint64_t randomNonce() {
  std::uint64_t n = 0;
  while (n == 0) RAND_bytes(reinterpret_cast<unsigned char*>(&n), sizeof n);
  return n;
}

// Offset samples kept (about 6 s of statuses at 5 a second): long enough to hold one taken on a
// quiet link, short enough that clock drift between machines does not matter.
constexpr size_t kOffsetSamples = 32;
// Heartbeats are ~100 bytes each; 200 a second keeps the backend's replay window (4,096
// sequences) longer than a command's 15 s of retransmission.
constexpr double kMaxHeartbeatHz = 200.0;
// With no watchdog (a stepped backend) heartbeats only carry the abandon-below mark.
constexpr double kHeartbeatHzWithoutWatchdog = 10.0;

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
  if (options_.heartbeats_per_watchdog > 0) heartbeat_ = std::thread([this] { heartbeatLoop(); });
}

RobotClient::~RobotClient() {
  {
    std::lock_guard lock(heartbeat_mutex_);
    stopping_ = true;
  }
  heartbeat_wake_.notify_all();
  if (heartbeat_.joinable()) heartbeat_.join();
}

// While connected, whatever the cycle is doing: the backend halts a motion when these stop or
// arrive late. Each carries its send time on the backend's clock, so a heartbeat delayed by the
// link (or by this thread's starvation before the send) counts as missing. Shares with the
// cycle only atomics and the socket (a send is one system call). It takes the highest priority
// the process may: a busy machine must not starve it into a false halt.
void RobotClient::heartbeatLoop() {
  {
    const std::string priority = raiseThreadPriority();
    std::lock_guard lock(priority_mutex_);
    heartbeat_priority_ = priority;
  }
  std::unique_lock lock(heartbeat_mutex_);
  while (!heartbeat_wake_.wait_for(lock, std::chrono::microseconds(heartbeat_period_us_.load()),
                                   [this] { return stopping_; })) {
    if (connected_ && offset_known_) {
      sendHeartbeat();
      ++thread_heartbeats_;
    }
  }
}

bool RobotClient::heartbeatsFlowing() const {
  return options_.heartbeats_per_watchdog <= 0 || watchdog_ms_ == 0 ||
         thread_heartbeats_.load() >= kStreamingHeartbeats;
}

// Stamped with its send time on the backend's clock. From the heartbeat thread, and once from
// the cycle's thread as the client binds: the backend holds a motion until a heartbeat shows
// the link fresh, so the first one must not wait for the thread's next turn.
void RobotClient::sendHeartbeat() {
  Message m = fresh(MessageType::Heartbeat, next_sequence_++);
  m.abandon_below = abandon_below_;
  m.time_us = steadyMicros() + offset_us_.load();
  socket_.sendTo(encode(m, key_), backend_);
}

std::optional<std::int64_t> RobotClient::clockOffsetUs() const {
  if (!offset_known_) return std::nullopt;
  return offset_us_.load();
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

// Every HELLO has a nonce of its own; the WELCOME that echoes one of the last few is the
// backend's answer now, not a copy of an old one.
void RobotClient::sendHello() {
  Message m = fresh(MessageType::Hello, next_sequence_++);
  m.nonce = randomNonce();
  hellos_.emplace_back(m.nonce, steadyMicros());
  if (hellos_.size() > 8) hellos_.erase(hellos_.begin());
  socket_.sendTo(encode(m, key_), backend_);
  next_hello_ = Clock::now() + seconds(hello_interval_);
  hello_interval_ = std::min(hello_interval_ * 2.0, options_.max_retransmit_s);
}

void RobotClient::sendStatus(std::uint64_t sequence, std::optional<double> clock_s) {
  Message m = fresh(MessageType::Status, sequence);
  m.clock_s = clock_s;
  status_sent_.emplace_back(sequence, steadyMicros());
  if (status_sent_.size() > 16) status_sent_.erase(status_sent_.begin());
  socket_.sendTo(encode(m, key_), backend_);
}

std::uint64_t RobotClient::send(MessageType type, const Vec3& target) {
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
  if (isMotion(p.type) && !heartbeatsFlowing()) {
    // Not before this client's heartbeat thread has shown it runs: the backend would hold the
    // motion anyway, and a first motion sent on a thread not yet scheduled could be halted.
    p.next_send = Clock::now() + std::chrono::milliseconds(2);
    return;
  }
  if (isMotion(p.type) && !p.epoch) {
    // Made after a RESET of this client that the backend has not confirmed: it waits for the
    // RESET's epoch (stamped with the old one it could never run).
    const bool reset_pending = std::any_of(pending_.begin(), pending_.end(), [&](const Pending& q) {
      return q.type == MessageType::Reset && q.sequence < p.sequence;
    });
    if (reset_pending) {
      p.next_send = Clock::now() + seconds(p.interval);
      return;
    }
    p.epoch = epoch_;
  }
  Message m = fresh(p.type, p.sequence);
  m.target = p.target;
  m.stop_epoch = p.epoch.value_or(0);
  socket_.sendTo(encode(m, key_), backend_);
  if (!p.transmitted) p.transmitted = true;
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

// The backend run this client was bound to is gone (a WELCOME answering this client's fresh
// HELLO came from another run): whatever was pending fails, saying whether it may have run on
// the old run; none is sent to the new run.
void RobotClient::restarted() {
  events_.push_back(event(RobotEvent::Kind::Restarted, "the backend restarted"));
  const std::vector<Pending> lost = pending_;
  for (const Pending& p : lost) {
    const std::string name = toString(p.type);
    std::string text =
        p.accepted ? name +
                         " ran on the backend's previous run, which restarted during it: how "
                         "far it got is unknown"
        : p.transmitted
            ? name +
                  " may have run: the backend restarted before answering it; it is not sent "
                  "to the new run"
            : name +
                  " not run: never sent before the backend restarted; it is not sent to the "
                  "new run";
    complete(p.sequence, failure(p.sequence, p.type, std::move(text), p.transmitted));
  }
  connected_ = false;
  boot_ = 0;
  offsets_.clear();
  offset_known_ = false;
}

void RobotClient::clockSample(std::int64_t sent_us, std::int64_t backend_us) {
  const std::int64_t now = steadyMicros();
  offsets_.emplace_back(now - sent_us, backend_us - (sent_us + now) / 2);
  if (offsets_.size() > kOffsetSamples) offsets_.erase(offsets_.begin());
  const auto best = std::min_element(offsets_.begin(), offsets_.end());
  offset_us_ = best->second;
  offset_known_ = true;
}

// A WELCOME echoing one of this client's recent nonces: the backend answers now. Another boot id
// than the bound one is a restart; either way the client answers the challenge (BIND).
bool RobotClient::welcome(const Message& m) {
  const auto asked = std::find_if(hellos_.begin(), hellos_.end(),
                                  [&](const auto& h) { return h.first == m.nonce; });
  if (asked == hellos_.end()) return false;  // an old WELCOME, or a replay: not an answer now
  const std::int64_t sent_us = asked->second;
  hellos_.clear();
  if (boot_ != 0 && m.boot != boot_) restarted();
  if (m.boot != boot_) offsets_.clear();
  clockSample(sent_us, m.time_us);
  binding_boot_ = m.boot;
  bind_challenge_ = m.challenge;
  bind_sequence_ = next_sequence_++;
  bind_started_ = Clock::now();
  bind_interval_ = options_.first_retransmit_s;
  watchdog_ms_ = m.watchdog_ms;
  const double hz =
      m.watchdog_ms == 0
          ? kHeartbeatHzWithoutWatchdog
          : std::min(kMaxHeartbeatHz, options_.heartbeats_per_watchdog * 1000.0 / m.watchdog_ms);
  heartbeat_period_us_ = std::llround(1e6 / hz);
  sendBind();
  return true;
}

// Retransmitted (the same sequence and challenge) until BOUND, as commands are.
void RobotClient::sendBind() {
  Message bind = fresh(MessageType::Bind, bind_sequence_);
  bind.boot = binding_boot_;
  bind.challenge = bind_challenge_;
  socket_.sendTo(encode(bind, key_), backend_);
  next_bind_ = Clock::now() + seconds(bind_interval_);
  bind_interval_ = std::min(bind_interval_ * 2.0, options_.max_retransmit_s);
}

// The backend took the BIND: commands go to this run now.
void RobotClient::bound(const Message& m) {
  bind_sequence_ = 0;
  boot_ = m.boot;
  epoch_ = m.stop_epoch;
  if (connected_) return;  // a rebinding (after silence): nothing else changes
  connected_ = true;
  thread_heartbeats_ = 0;
  events_.push_back(event(
      RobotEvent::Kind::Connected,
      "bound to backend run " + std::to_string(m.boot) +
          (watchdog_ms_ ? ", watchdog " + std::to_string(watchdog_ms_) + " ms" : ", no watchdog")));
  next_status_ = Clock::now();
  // Before any command: the backend holds a motion until a heartbeat has come.
  if (options_.heartbeats_per_watchdog > 0) sendHeartbeat();
  for (Pending& p : pending_) transmit(p);
}

void RobotClient::handle(const Message& m) {
  if (m.session != session_ || isCommand(m.type)) return;
  const double skew =
      std::abs(static_cast<double>(wallClockMs()) - static_cast<double>(m.timestamp_ms)) / 1000.0;
  if (skew > 30.0) return;  // a stale reply: ignore it
  if (m.type == MessageType::Welcome) {
    if (!welcome(m)) return;
  } else if (m.type == MessageType::Bound && bind_sequence_ != 0 && m.sequence == bind_sequence_ &&
             m.boot == binding_boot_) {
    bound(m);
  } else if (boot_ == 0 || m.boot != boot_) {
    // From a run this client is not bound to: a replayed reply, or a sign of a restart. Only a
    // WELCOME answering a fresh HELLO can tell which, so ask (at the HELLO back-off).
    if (bind_sequence_ == 0 && Clock::now() >= next_hello_) sendHello();
    return;
  }
  last_heard_ = Clock::now();
  heard_ = true;
  if (silent_) {
    silent_ = false;
    events_.push_back(event(RobotEvent::Kind::Reachable, "the backend answers again"));
  }
  if (!connected_ || m.boot != boot_) return;
  Pending* p = find(m.sequence);
  switch (m.type) {
    case MessageType::Accepted:
      epoch_ = std::max(epoch_, m.stop_epoch);
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
      epoch_ = std::max(epoch_, m.status.stop_epoch);
      const auto asked = std::find_if(status_sent_.begin(), status_sent_.end(),
                                      [&](const auto& q) { return q.first == m.sequence; });
      if (asked != status_sent_.end()) {
        clockSample(asked->second, m.status.backend_time_us);
        status_sent_.erase(asked);
      }
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
    if (decoded.ok()) {
      handle(decoded.message);
    } else if (decoded.error == DecodeError::BadMac) {
      // A backend whose key differs says so, sealed with no key: reported, never acted on.
      const Decoded refusal = decode(datagram->bytes.data(), datagram->bytes.size(), kNoKey);
      if (refusal.ok() && refusal.message.type == MessageType::KeyMismatch &&
          refusal.message.session == session_)
        key_refused_ = true;
    }
  }
  const auto now = Clock::now();
  // Answering a challenge: BIND until BOUND; a challenge unanswered for long may have expired
  // (or its WELCOME came from a run now gone): start again with a HELLO.
  if (bind_sequence_ != 0) {
    if (now - bind_started_ > seconds(2.0)) {
      bind_sequence_ = 0;
    } else if (now >= next_bind_) {
      sendBind();
    }
  }
  // Not bound (or silent, when the backend may have lost our address): HELLO, with back-off.
  if ((!connected_ || silent_) && bind_sequence_ == 0 && now >= next_hello_) sendHello();
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
    const std::string name = toString(p.type);
    complete(
        p.sequence,
        failure(p.sequence, p.type,
                p.transmitted ? name + " may have run: sent, but no answer from the backend (given "
                                       "up; the backend will not start it later once it hears this "
                                       "client's heartbeat)"
                              : name + " not run: never sent, no backend run bound this client",
                p.transmitted));
  }
  if (connected_ && now >= next_status_) {
    next_status_ = now + seconds(options_.status_interval_s);
    sendStatus(next_sequence_++, std::nullopt);
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
      sendStatus(sync_sequence_, clock_s);
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
