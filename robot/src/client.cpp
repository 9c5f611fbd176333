#include "arbci/robot/client.h"

#include <openssl/rand.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace arbci::robot {
namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
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
  }
  return "unknown";
}

RobotClient::RobotClient(const Endpoint& backend, const Key& key, const ClientOptions& options)
    : backend_(backend), key_(key), options_(options), socket_(0, "0.0.0.0") {
  RAND_bytes(reinterpret_cast<unsigned char*>(&session_), sizeof session_);
  created_ = last_heard_ = next_status_ = Clock::now();
}

RobotClient::~RobotClient() = default;

std::uint64_t RobotClient::send(MessageType type, const Vec3& target) {
  Pending p;
  p.sequence = next_sequence_++;
  p.type = type;
  p.target = target;
  p.first_sent = Clock::now();
  p.interval = options_.first_retransmit_s;
  transmit(p);
  pending_.push_back(p);
  return p.sequence;
}

void RobotClient::transmit(Pending& p) {
  Message m;
  m.type = p.type;
  m.session = session_;
  m.sequence = p.sequence;
  m.timestamp_ms = wallClockMs();
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

void RobotClient::complete(std::uint64_t sequence, RobotEvent event) {
  std::erase_if(pending_, [&](const Pending& p) { return p.sequence == sequence; });
  events_.push_back(std::move(event));
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
    events_.push_back(
        {RobotEvent::Kind::Reachable, 0, MessageType::Status, {}, {}, "the backend answers again"});
  }
  if (boot_ != 0 && m.boot != boot_) {
    events_.push_back(
        {RobotEvent::Kind::Restarted, 0, MessageType::Status, {}, {}, "the backend restarted"});
    // Accepted commands died with the old backend: they must not be taken for done.
    std::vector<Pending> lost;
    for (const Pending& p : pending_) {
      if (p.accepted && p.accepted_boot != m.boot) lost.push_back(p);
    }
    for (const Pending& p : lost) {
      complete(p.sequence,
               {RobotEvent::Kind::Failed,
                p.sequence,
                p.type,
                {},
                Outcome::Failed,
                std::string(toString(p.type)) + " lost: the backend restarted during the command"});
    }
  }
  boot_ = m.boot;
  Pending* p = find(m.sequence);
  switch (m.type) {
    case MessageType::Accepted:
      if (p && !p->accepted) {
        p->accepted = true;
        p->accepted_boot = m.boot;
        events_.push_back({RobotEvent::Kind::Accepted, p->sequence, p->type, {}, {}, ""});
        if (p->type == MessageType::Stop)
          complete(
              p->sequence,
              {RobotEvent::Kind::Finished, p->sequence, p->type, {}, Outcome::Success, "stopped"});
      }
      break;
    case MessageType::Rejected:
      if (p)
        complete(p->sequence,
                 {RobotEvent::Kind::Rejected, p->sequence, p->type, m.reason, {}, m.text});
      break;
    case MessageType::Finished:
      if (p && (!p->accepted || p->accepted_boot == m.boot)) {
        complete(p->sequence,
                 {RobotEvent::Kind::Finished, p->sequence, p->type, {}, m.outcome, m.text});
      }
      break;
    case MessageType::StatusReply: {
      status_ = m.status;
      if (sync_sequence_ != 0 && m.sequence == sync_sequence_) synced_ = true;
      // A lost FINISHED shows in the status as this session's last finished command.
      Pending* done = find(m.status.last_finished_sequence);
      if (done && done->accepted && done->accepted_boot == m.boot) {
        complete(done->sequence, {RobotEvent::Kind::Finished,
                                  done->sequence,
                                  done->type,
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
  std::vector<Pending> expired;
  for (Pending& p : pending_) {
    if (p.accepted) continue;
    if (now - p.first_sent > seconds(options_.give_up_s)) {
      expired.push_back(p);
    } else if (now >= p.next_send) {
      transmit(p);
    }
  }
  for (const Pending& p : expired) {
    complete(p.sequence,
             {RobotEvent::Kind::Failed,
              p.sequence,
              p.type,
              {},
              Outcome::Failed,
              std::string(toString(p.type)) + " was never accepted: no answer from the backend"});
  }
  if (now >= next_status_) {
    next_status_ = now + seconds(options_.status_interval_s);
    Message m;
    m.type = MessageType::Status;
    m.session = session_;
    m.sequence = next_sequence_++;
    m.timestamp_ms = wallClockMs();
    socket_.sendTo(encode(m, key_), backend_);
  }
  const auto quiet_since = heard_ ? last_heard_ : created_;
  if (!silent_ && now - quiet_since > seconds(options_.silence_s)) {
    silent_ = true;
    events_.push_back({RobotEvent::Kind::Silent,
                       0,
                       MessageType::Status,
                       {},
                       {},
                       "no answer from the backend for a second"});
  }
}

bool RobotClient::syncClock(double clock_s, double timeout_s) {
  Message m;
  m.type = MessageType::Status;
  m.session = session_;
  m.sequence = sync_sequence_ = next_sequence_++;
  m.clock_s = clock_s;
  synced_ = false;
  const auto give_up = Clock::now() + seconds(timeout_s);
  auto resend = Clock::now();
  while (!synced_ && Clock::now() < give_up) {
    if (Clock::now() >= resend) {
      m.timestamp_ms = wallClockMs();
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
