#include "arbci/robot/backend.h"

#include <openssl/rand.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>
#include <utility>

#include "arbci/robot/thread_priority.h"

namespace arbci::robot {
namespace {

using SteadyClock = std::chrono::steady_clock;
constexpr size_t kCachedReplies = 256;
constexpr auto kSessionLifetime = std::chrono::minutes(5);
// A WELCOME's challenge must be answered within this long; a session keeps this many open (a
// replayed HELLO adds one without displacing the real client's).
constexpr auto kChallengeLifetime = std::chrono::seconds(5);
constexpr size_t kChallengesPerSession = 4;
constexpr size_t kMaxChallenges = 256;
// The watchdog looks this much before its deadline, so that waking from the socket wait (tens of
// microseconds, more on a busy machine) does not carry the halt past the watchdog time.
constexpr std::int64_t kWakeMarginUs = 1000;
// Source addresses whose unbound budget is remembered at once (see SourceBudgets::forgetQuiet).
constexpr size_t kBudgetedSources = 1024;

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

// A budget of `rate` a second, at most one second's worth saved up.
class TokenBucket {
 public:
  explicit TokenBucket(double rate) : rate_(rate), tokens_(rate) {}
  bool take(SteadyClock::time_point now) {
    tokens_ = std::min(rate_, tokens_ + rate_ * std::chrono::duration<double>(now - last_).count());
    last_ = now;
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

 private:
  double rate_, tokens_;
  SteadyClock::time_point last_ = SteadyClock::now();
};

// The unbound budget, one per source address: a flood from one address (or a few) spends its own
// and never the budget of a new client's HELLO, BIND or STOP from another.
class SourceBudgets {
 public:
  explicit SourceBudgets(double rate) : rate_(rate) {}
  bool take(const Endpoint& from, SteadyClock::time_point now) {
    const std::uint64_t key = (std::uint64_t{from.address.sin_addr.s_addr} << 16) |
                              from.address.sin_port;  // address and port, as received
    auto found = budgets_.find(key);
    if (found == budgets_.end()) {
      if (budgets_.size() >= kBudgetedSources) forgetQuiet(now);
      found = budgets_.emplace(key, Entry{TokenBucket(rate_), now}).first;
    }
    found->second.heard = now;
    return found->second.bucket.take(now);
  }

 private:
  struct Entry {
    TokenBucket bucket;
    SteadyClock::time_point heard;
  };
  // Addresses quiet for a second have a full budget again: forgetting them changes nothing. When
  // every one spoke within the second (a flood forging a new address each time), all are
  // forgotten: each new address starts with a full budget either way. Once per kBudgetedSources
  // new addresses at most, so a flood of new addresses costs no scan per datagram.
  void forgetQuiet(SteadyClock::time_point now) {
    std::erase_if(budgets_, [&](const auto& entry) {
      return now - entry.second.heard >= std::chrono::seconds(1);
    });
    if (budgets_.size() >= kBudgetedSources) budgets_.clear();
  }
  double rate_;
  std::map<std::uint64_t, Entry> budgets_;
};

}  // namespace

struct RobotBackend::Impl {
  Key key;
  std::unique_ptr<RobotDriver> driver;
  BackendOptions options;
  UdpSocket socket;
  std::uint64_t boot = randomId();
  // Motion commands must carry this; RESET starts the next, so whatever was made before a STOP
  // (in an older epoch) never runs.
  std::uint64_t stop_epoch = 1;

  struct Session {
    Endpoint peer;  // bound by a BIND: every reply to this session goes there
    std::uint64_t highest = 0;
    std::set<std::uint64_t> seen;              // within the window
    std::map<std::uint64_t, Message> replies;  // cached answers to commands, by sequence
    std::uint64_t last_finished = 0;
    Outcome last_outcome = Outcome::Success;
    std::string last_text;
    // Motion commands below this sequence never start: abandoned by the client (its heartbeat).
    std::uint64_t abandon_below = 0;
    // The send time (this backend's clock) of the newest heartbeat, never later than its receipt.
    std::optional<std::int64_t> heartbeat_us;
    // How old the heartbeat received last was when it arrived: over the watchdog, the link
    // delays it too much to protect a motion (a lost heartbeat sets nothing here).
    std::int64_t last_heartbeat_age_us = 0, heartbeat_received_us = 0;
    // The challenge of the BIND that bound it: a retransmission of that BIND from the bound
    // address is answered again (its BOUND may have been lost).
    std::uint64_t bound_challenge = 0, bind_sequence = 0;
    SteadyClock::time_point active;
    // A motion that came before the session's heartbeats arrive at their rate (since when, on
    // this backend's clock): it starts once they do, fresh, and is refused when they arrive stale
    // or do not come.
    std::optional<Message> held;
    std::int64_t held_us = 0;
    // Heartbeats received, and when the one before the last arrived.
    int heartbeats = 0;
    std::int64_t previous_received_us = 0;
    bool held_since = false;  // held_us is the first hold's (a motion held again keeps it)
  };
  std::map<std::uint64_t, Session> sessions;

  // WELCOMEs sent and not yet answered by a BIND, by session.
  struct Challenge {
    std::uint64_t client_nonce = 0, backend_nonce = 0, hello_sequence = 0;
    SteadyClock::time_point sent;
  };
  std::map<std::uint64_t, std::vector<Challenge>> challenges;

  struct Running {
    std::uint64_t session = 0, sequence = 0;
    MessageType type = MessageType::Home;
    std::int64_t started_us = 0;
  };
  std::optional<Running> running;
  std::string stop_reason;              // a latched stop: motion commands are refused until a RESET
  std::optional<double> stepped_clock;  // stepped: the clock the robot has reached
  SteadyClock::time_point last_step = SteadyClock::now(), last_push = SteadyClock::now();
  SourceBudgets unbound_budget;
  TokenBucket refusal_budget;
  BackendStats stats;
  mutable std::mutex stats_mutex;
  std::string priority;
  std::map<std::string, SteadyClock::time_point> last_log;

  Impl(const Key& k, std::unique_ptr<RobotDriver> d, const BackendOptions& o)
      : key(k),
        driver(std::move(d)),
        options(o),
        socket(o.port, o.host),
        unbound_budget(o.unbound_per_s),
        refusal_budget(o.refusals_per_s) {
    if (options.receive_buffer_bytes > 0) socket.setReceiveBuffer(options.receive_buffer_bytes);
  }

  bool watchdogActive() const { return !options.stepped && options.watchdog_s > 0.0; }
  std::int64_t watchdogMicros() const { return std::llround(options.watchdog_s * 1e6); }

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

  std::vector<std::uint8_t> stamped(const Message& m) {
    Message out = m;
    out.boot = boot;
    out.timestamp_ms = wallClockMs();
    return encode(out, key);
  }

  void send(const Message& m, const Endpoint& to) { socket.sendTo(stamped(m), to); }

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
    // Stopped is the latch: once a RESET lifts it, an arm that stands still is idle.
    s.state = !stop_reason.empty()                                     ? RobotState::Stopped
              : d.state == RobotState::Stopped && !running.has_value() ? RobotState::Idle
                                                                       : d.state;
    s.stop_reason = stop_reason;
    s.stop_epoch = stop_epoch;
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
    s.backend_time_us = steadyMicros();
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
  void latchStop(const std::string& reason, const std::string& outcome_text,
                 const std::string& detail = "") {
    const bool halted = running.has_value();
    const std::string what = halted ? toString(running->type) + std::string(" halted") : "";
    driver->stop();
    finish(Outcome::Stopped, outcome_text);
    for (auto& [id, session] : sessions) {
      if (!session.held) continue;
      const Message held = *std::exchange(session.held, std::nullopt);
      reject(held, session.peer, RejectReason::Stopped,
             "the robot was stopped (" + reason + ") before the command could start");
    }
    const bool latched = stop_reason.empty();
    if (latched) stop_reason = reason;
    if (halted || latched) {
      note("stopped: " + reason + (halted ? " (" + what + ")" : "") +
           "; motion commands refused until RESET" + detail);
    } else {
      log("stop again", "stopped again: " + reason + " (already stopped: " + stop_reason + ")");
    }
  }

  // Whether a datagram deserves a MAC check: from a bound session's own address always (the
  // real client's STOP and heartbeats are never crowded out); anything else within its source
  // address's budget, so a flood of forgeries costs a header read each and a new client's
  // datagrams from another address are still read.
  bool worthVerifying(const Datagram& d, bool from_bound_peer, SteadyClock::time_point now) {
    if (from_bound_peer || unbound_budget.take(d.from, now)) return true;
    count(&BackendStats::shed);
    log("shed", "dropped datagrams unread (not from a bound client, over " +
                    std::to_string(static_cast<int>(options.unbound_per_s)) +
                    " a second from one address), e.g. from " + d.from.toString());
    return false;
  }

  bool fromBoundPeer(const Datagram& d) const {
    const auto header = peek(d.bytes.data(), d.bytes.size());
    if (!header) return false;
    const auto found = sessions.find(header->session);
    return found != sessions.end() && found->second.peer == d.from;
  }

  // `from_bound_peer`: fromBoundPeer(d), which the poll loop has sorted the batch by.
  void handle(const Datagram& d, bool from_bound_peer) {
    count(&BackendStats::datagrams);
    if (!worthVerifying(d, from_bound_peer, SteadyClock::now())) return;
    const Decoded decoded = decode(d.bytes.data(), d.bytes.size(), key);
    if (!decoded.ok()) {
      {
        std::lock_guard lock(stats_mutex);
        ++stats.ignored;
        ++stats.by_error[decoded.error];
      }
      log(toString(decoded.error),
          "ignored a datagram from " + d.from.toString() + ": " + toString(decoded.error));
      if (decoded.error == DecodeError::BadMac) keyMismatch(d);
      return;
    }
    const Message& m = decoded.message;
    if (!isCommand(m.type)) {
      count(&BackendStats::ignored);
      return;  // a reply sent to the backend: nothing to do
    }
    const auto found = sessions.find(m.session);
    const double skew =
        std::abs(static_cast<double>(wallClockMs()) - static_cast<double>(m.timestamp_ms)) / 1000.0;
    if (skew > options.max_clock_skew_s) {
      stale(m, d, RejectReason::Replayed,
            "timestamp " + std::to_string(static_cast<long>(skew)) + " s off");
      return;
    }
    if (m.type == MessageType::Hello) {
      hello(m, d.from);
      return;
    }
    if (m.boot != boot) {
      // Sent to another run of the backend (a capture replayed after a restart, or a client
      // that has not noticed the restart yet): never run; the client learns it must HELLO.
      stale(m, d, RejectReason::UnknownBoot, "backend restarted: HELLO");
      return;
    }
    if (m.type == MessageType::Bind) {
      bind(m, d.from);
      return;
    }
    if (found == sessions.end()) {
      stale(m, d, RejectReason::NotAuthenticated, "no BIND in this run");
      return;
    }
    Session& s = found->second;
    if (belowWindow(m.sequence, s.highest)) {
      reject(m, s.peer, RejectReason::Replayed,
             "sequence " + std::to_string(m.sequence) + " is older than the replay window");
      return;
    }
    if (s.seen.count(m.sequence)) {
      if (s.held && s.held->sequence == m.sequence) return;  // still waiting for a heartbeat
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
    s.active = SteadyClock::now();
    process(m, s);
    while (s.replies.size() > kCachedReplies) s.replies.erase(s.replies.begin());
  }

  // A stale or unplaceable command (old timestamp, another run, no session): answered at the
  // session's bound address when there is one; otherwise only with a refusal smaller than the
  // datagram and within the refusal budget, so the backend cannot be used to reflect or
  // amplify traffic towards a forged sender address.
  void stale(const Message& m, const Datagram& d, RejectReason reason, const std::string& text) {
    count(&BackendStats::replayed);
    const bool answered = answerStale(m, d, reason, text);
    log(toString(reason), std::string(answered ? "refused " : "ignored (not answered) ") +
                              toString(m.type) + " from " + d.from.toString() + ": " + text);
  }

  // Whether a refusal was sent (see stale()).
  bool answerStale(const Message& m, const Datagram& d, RejectReason reason,
                   const std::string& text) {
    if (m.type == MessageType::Heartbeat || m.type == MessageType::Bind) return false;
    Message r = reply(m, MessageType::Rejected);
    r.reason = reason;
    r.text = text;
    if (const auto found = sessions.find(m.session); found != sessions.end()) {
      if (!refusal_budget.take(SteadyClock::now())) return false;
      send(r, found->second.peer);
      return true;
    }
    r.text.clear();  // the reason is enough; the least sent to an address nobody bound
    const auto bytes = stamped(r);
    if (bytes.size() >= d.bytes.size() || !refusal_budget.take(SteadyClock::now())) return false;
    socket.sendTo(bytes, d.from);
    return true;
  }

  // A HELLO sealed with another key: the client is told its key is not this backend's (a wrong
  // key file otherwise looks like no backend at all). Sealed with no key, it says nothing secret,
  // is smaller than the HELLO and within the unbound budget.
  void keyMismatch(const Datagram& d) {
    const auto header = peek(d.bytes.data(), d.bytes.size());
    if (!header || header->type != MessageType::Hello) return;
    Message m;
    m.type = MessageType::KeyMismatch;
    m.session = header->session;
    m.boot = boot;
    m.timestamp_ms = wallClockMs();
    const auto bytes = encode(m, kNoKey);
    if (bytes.size() < d.bytes.size() && refusal_budget.take(SteadyClock::now()))
      socket.sendTo(bytes, d.from);
  }

  // HELLO asks for a challenge; it binds nothing, so a replayed one cannot move a session. Its
  // WELCOME is no larger than the HELLO (which is padded to its size) and within the unbound
  // budget, like every datagram not from a bound address.
  void hello(const Message& m, const Endpoint& from) {
    const auto found = sessions.find(m.session);
    if (found != sessions.end() && m.sequence <= found->second.highest) {
      count(&BackendStats::replayed);
      log("old hello", "ignored HELLO " + std::to_string(m.sequence) + " from " + from.toString() +
                           ": not newer than the session's last");
      return;
    }
    const auto now = SteadyClock::now();
    auto& open = challenges[m.session];
    std::erase_if(open, [&](const Challenge& c) { return now - c.sent > kChallengeLifetime; });
    auto same = std::find_if(open.begin(), open.end(),
                             [&](const Challenge& c) { return c.client_nonce == m.nonce; });
    if (same == open.end()) {
      // A copy of a HELLO gets the same challenge again; a new nonce a new one.
      if (open.size() >= kChallengesPerSession) open.erase(open.begin());
      open.push_back({m.nonce, randomId(), m.sequence, now});
      same = open.end() - 1;
    }
    if (challenges.size() > kMaxChallenges) {
      // Forget the session whose newest challenge is the oldest (never the one just made).
      auto oldest = challenges.end();
      for (auto it = challenges.begin(); it != challenges.end(); ++it) {
        if (it->first == m.session || it->second.empty()) continue;
        if (oldest == challenges.end() || it->second.back().sent < oldest->second.back().sent)
          oldest = it;
      }
      if (oldest != challenges.end()) challenges.erase(oldest);
    }
    Message welcome = reply(m, MessageType::Welcome);
    welcome.watchdog_ms =
        watchdogActive() ? static_cast<std::uint32_t>(std::lround(options.watchdog_s * 1000)) : 0;
    welcome.nonce = m.nonce;
    welcome.challenge = same->backend_nonce;
    welcome.stop_epoch = stop_epoch;
    welcome.time_us = steadyMicros();
    send(welcome, from);
  }

  // BIND answers one of this session's open challenges: the client holds the key and saw this
  // run's WELCOME just now. Binds the session to this run and to the sender's address.
  void bind(const Message& m, const Endpoint& from) {
    auto open = challenges.find(m.session);
    const auto now = SteadyClock::now();
    if (const auto known = sessions.find(m.session);
        known != sessions.end() && known->second.bound_challenge == m.challenge &&
        known->second.bind_sequence == m.sequence && known->second.peer == from) {
      count(&BackendStats::duplicates);
      Message bound = reply(m, MessageType::Bound);
      bound.stop_epoch = stop_epoch;
      send(bound, from);
      return;
    }
    auto matches = [&](const Challenge& c) {
      return c.backend_nonce == m.challenge && now - c.sent <= kChallengeLifetime &&
             m.sequence > c.hello_sequence;
    };
    if (open == challenges.end() ||
        std::none_of(open->second.begin(), open->second.end(), matches)) {
      count(&BackendStats::replayed);
      log("bind", "ignored BIND from " + from.toString() + ": no open challenge matches it");
      return;
    }
    challenges.erase(open);  // answered: every open challenge of the session is spent
    Session& s = sessions[m.session];
    // A rebinding session has sent heartbeats since; its BIND is new if its sequence is unused
    // and inside the replay window (the challenge already proved it fresh).
    if (s.seen.count(m.sequence) || belowWindow(m.sequence, s.highest)) {
      count(&BackendStats::replayed);
      return;
    }
    s.peer = from;
    s.highest = std::max(s.highest, m.sequence);
    s.seen.insert(m.sequence);
    s.active = now;
    s.bound_challenge = m.challenge;
    s.bind_sequence = m.sequence;
    Message bound = reply(m, MessageType::Bound);
    bound.stop_epoch = stop_epoch;
    send(bound, from);
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
    Message accepted = reply(m, MessageType::Accepted);
    accepted.stop_epoch = stop_epoch;
    s.replies[m.sequence] = accepted;
    send(accepted, s.peer);
  }

  // A heartbeat's send time, as the client puts it on this backend's clock: one sent longer ago
  // than the watchdog (a delayed link, a client that stalled before sending) feeds nothing.
  void heartbeat(const Message& m, Session& s) {
    const std::int64_t now = steadyMicros();
    const std::int64_t sent = std::min(m.time_us, now);  // a clock error cannot extend the deadline
    s.last_heartbeat_age_us = now - sent;
    ++s.heartbeats;
    s.previous_received_us = s.heartbeat_received_us;
    s.heartbeat_received_us = now;
    if (watchdogActive() && now - sent > watchdogMicros()) count(&BackendStats::stale_heartbeats);
    if (!s.heartbeat_us || sent > *s.heartbeat_us) s.heartbeat_us = sent;
    s.abandon_below = std::max(s.abandon_below, m.abandon_below);
    if (running && running->session == m.session && running->sequence < s.abandon_below)
      latchStop("halted: the client gave up on the command",
                "halted: the client gave up on the command");
    // The link has shown how old its heartbeats arrive, and whether they come at their rate: a
    // held motion starts, is refused, or waits for the next.
    if (s.held) motion(*std::exchange(s.held, std::nullopt), s);
  }

  // One heartbeat alone (a client sends one as it binds, from its command thread) shows nothing
  // of the thread that must keep feeding the watchdog while the arm moves (kStreamingHeartbeats).
  bool streaming(const Session& s) const {
    return s.heartbeats >= kStreamingHeartbeats &&
           s.heartbeat_received_us - s.previous_received_us <= watchdogMicros() / 2;
  }

  void process(const Message& m, Session& s) {
    switch (m.type) {
      case MessageType::Status:
        if (options.stepped && m.clock_s) stepTo(*m.clock_s);
        send(statusFor(m.session, m.sequence), s.peer);
        return;
      case MessageType::Heartbeat:
        heartbeat(m, s);
        return;
      case MessageType::Stop:
        latchStop("emergency stop", "stopped by STOP");
        accept(m, s);
        return;
      case MessageType::Reset:
        if (!stop_reason.empty()) {
          // Commands made before now carry an older epoch: none of them runs, from any client.
          ++stop_epoch;
          note("RESET: the stop (" + stop_reason + ") is lifted; stop epoch " +
               std::to_string(stop_epoch));
        }
        stop_reason.clear();
        accept(m, s);
        return;
      default:
        if (isMotion(m.type)) motion(m, s);
    }
  }

  // Why a motion's stop epoch is not this run's (reason 11).
  std::string wrongEpoch(const Message& m) const {
    const std::string command = std::string(toString(m.type)) + " " + std::to_string(m.sequence);
    const std::string now = " (epoch now " + std::to_string(stop_epoch) + ")";
    if (m.stop_epoch == 0)
      return command + " carries no stop epoch (0)" + now +
             ": a motion must carry the epoch of the WELCOME, BOUND or ACCEPTED last received; it "
             "never runs";
    if (m.stop_epoch > stop_epoch)
      return command + " carries stop epoch " + std::to_string(m.stop_epoch) +
             ", which this backend run has not reached" + now + ": it never runs";
    return command + " was made in stop epoch " + std::to_string(m.stop_epoch) +
           ", before the STOP that a RESET lifted" + now +
           ": it never runs; send it again if it is still wanted";
  }

  void motion(const Message& m, Session& s) {
    if (!stop_reason.empty()) {
      reject(m, s.peer, RejectReason::Stopped,
             "the robot is stopped (" + stop_reason + "): RESET first");
      return;
    }
    if (m.stop_epoch != stop_epoch) {
      reject(m, s.peer, RejectReason::BeforeStop, wrongEpoch(m));
      return;
    }
    if (m.sequence < s.abandon_below) {
      reject(m, s.peer, RejectReason::Cancelled,
             "sequence " + std::to_string(m.sequence) + " was given up by the client");
      return;
    }
    if (s.held) {
      reject(m, s.peer, RejectReason::Busy,
             std::string("busy: ") + toString(s.held->type) + " " +
                 std::to_string(s.held->sequence) +
                 " waits for the client's heartbeats to come at their rate");
      return;
    }
    if (running) {
      reject(m, s.peer, RejectReason::Busy,
             std::string("busy with ") + toString(running->type) + " " +
                 std::to_string(running->sequence));
      return;
    }
    const std::int64_t now_us = steadyMicros();
    if (watchdogActive() && !streaming(s) && s.last_heartbeat_age_us <= watchdogMicros()) {
      // Its heartbeats not yet coming at their rate: nothing shows that they will go on coming
      // while the arm moves, so the watchdog could halt a healthy client's motion. Held (since its
      // first arrival) until they do.
      if (!s.held_since) s.held_us = now_us;
      s.held = m;
      s.held_since = true;
      return;
    }
    s.held_since = false;
    if (watchdogActive() && s.last_heartbeat_age_us > watchdogMicros()) {
      // The link delays the heartbeats past the watchdog: it could not halt the arm in time.
      reject(m, s.peer, RejectReason::Unreachable,
             "the last heartbeat arrived " + std::to_string(s.last_heartbeat_age_us / 1000) +
                 " ms after it was sent, over the watchdog's " +
                 std::to_string(watchdogMicros() / 1000) +
                 " ms: the link is too slow to move safely");
      return;
    }
    const DriverCommand command{m.type, m.target};
    if (const auto refusal = driver->check(command)) {
      reject(m, s.peer, refusal->reason, refusal->text);
      return;
    }
    driver->start(command);
    running = Running{m.session, m.sequence, m.type, now_us};
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

  // When the watchdog halts the running motion (nothing when none runs): the watchdog time after
  // the later of its start and the newest heartbeat's send time.
  std::optional<std::int64_t> watchdogDeadlineUs() const {
    if (!running || !watchdogActive()) return std::nullopt;
    std::int64_t fed = running->started_us;
    const auto found = sessions.find(running->session);
    if (found != sessions.end() && found->second.heartbeat_us)
      fed = std::max(fed, *found->second.heartbeat_us);
    return fed + watchdogMicros() - kWakeMarginUs;
  }

  // Why the watchdog fired, for the log: how old the newest heartbeat is and when one last came.
  std::string watchdogDetail() const {
    const auto found = running ? sessions.find(running->session) : sessions.end();
    if (found == sessions.end() || !found->second.heartbeat_us) return " (no heartbeat yet)";
    const Session& s = found->second;
    const std::int64_t now = steadyMicros();
    return " (newest heartbeat sent " + std::to_string((now - *s.heartbeat_us) / 1000) +
           " ms ago; the last to arrive was " + std::to_string(s.last_heartbeat_age_us / 1000) +
           " ms old, " + std::to_string((now - s.heartbeat_received_us) / 1000) + " ms ago)";
  }

  void advance() {
    const auto now = SteadyClock::now();
    if (const auto deadline = watchdogDeadlineUs(); deadline && steadyMicros() >= *deadline) {
      latchStop("halted: link lost", "halted: link lost (no fresh heartbeat from the client)",
                watchdogDetail());
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
    for (auto& [id, s] : sessions) {
      const std::int64_t wait_us = std::llround(options.first_heartbeat_wait_s * 1e6);
      if (!s.held || steadyMicros() - s.held_us < wait_us) continue;
      const Message held = *std::exchange(s.held, std::nullopt);
      s.held_since = false;
      reject(held, s.peer, RejectReason::Unreachable,
             "the client's heartbeats did not come at their rate within " +
                 std::to_string(wait_us / 1000) + " ms of its " + toString(held.type) + " (" +
                 std::to_string(s.heartbeats) +
                 " received): the link has not shown that the watchdog could halt the arm in "
                 "time");
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
  if (const auto deadline = m.watchdogDeadlineUs()) {
    wait = std::clamp(std::chrono::microseconds(*deadline - steadyMicros()),
                      std::chrono::microseconds(0), wait);
  }
  m.socket.wait(wait);
  // Bounded, so a flood cannot starve the arm; the bound clients' datagrams (a STOP, the
  // heartbeats) are handled before the rest of the batch.
  std::vector<Datagram> later;
  for (int i = 0; i < 256; ++i) {
    auto datagram = m.socket.receive();
    if (!datagram) break;
    if (m.fromBoundPeer(*datagram)) {
      m.handle(*datagram, true);
    } else {
      later.push_back(std::move(*datagram));
    }
  }
  // Checked again: a BIND earlier in the batch may have bound one of these.
  for (const Datagram& d : later) m.handle(d, m.fromBoundPeer(d));
  m.advance();
}

void RobotBackend::run(const std::atomic<bool>& stop) {
  if (impl_->options.raise_priority) {
    const std::string got = raiseThreadPriority();
    std::lock_guard lock(impl_->stats_mutex);
    impl_->priority = got;
  }
  while (!stop.load()) poll(5);
}

BackendStats RobotBackend::stats() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->stats;
}

std::string RobotBackend::priority() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->priority;
}

}  // namespace arbci::robot
