#include "support/udp_relay.h"

#include <utility>

#include "arbci/robot/thread_priority.h"

namespace arbci::test {

UdpRelay::UdpRelay(int backend_port, const robot::Key& key, unsigned seed, bool real_time)
    : backend_(robot::Endpoint::resolve("127.0.0.1", backend_port)), key_(key), random_(seed) {
  thread_ = std::thread([this, real_time] {
    // A network does not stall because the PC is busy: at the priority the link's own ends take.
    if (real_time) robot::raiseThreadPriority();
    run();
  });
}

double UdpRelay::takeLongestStallMs() {
  return static_cast<double>(longest_stall_us_.exchange(0)) / 1000.0;
}

UdpRelay::~UdpRelay() {
  stop_ = true;
  thread_.join();
}

void UdpRelay::setLoss(double to_backend, double to_client) {
  std::lock_guard lock(mutex_);
  loss_to_backend_ = to_backend;
  loss_to_client_ = to_client;
}

void UdpRelay::setCut(bool cut) {
  std::lock_guard lock(mutex_);
  cut_ = cut;
}

void UdpRelay::setDelay(std::chrono::milliseconds delay, bool to_backend_only) {
  std::lock_guard lock(mutex_);
  delay_ = delay;
  delay_to_backend_only_ = to_backend_only;
}

// Called with the mutex held.
void UdpRelay::forward(Bytes bytes, bool to_backend) {
  if (delay_.count() > 0 && (to_backend || !delay_to_backend_only_)) {
    delayed_.push_back({std::chrono::steady_clock::now() + delay_, std::move(bytes), to_backend});
  } else if (to_backend) {
    back_.sendTo(bytes, backend_);
  } else if (client_) {
    front_.sendTo(bytes, *client_);
  }
}

void UdpRelay::hold(robot::MessageType command) {
  std::lock_guard lock(mutex_);
  holding_.insert(command);
}

void UdpRelay::release(std::uint64_t sequence) {
  std::lock_guard lock(mutex_);
  for (const auto& [held_sequence, bytes] : held_) {
    if (held_sequence == sequence) back_.sendTo(bytes, backend_);
  }
  std::erase_if(held_, [&](const auto& held) { return held.first == sequence; });
}

void UdpRelay::stopHolding() {
  std::lock_guard lock(mutex_);
  holding_.clear();
}

void UdpRelay::dropReplies(std::set<robot::MessageType> types) {
  std::lock_guard lock(mutex_);
  dropping_ = std::move(types);
}

std::vector<UdpRelay::Bytes> UdpRelay::captured(robot::MessageType command) const {
  std::lock_guard lock(mutex_);
  std::vector<Bytes> out;
  for (const auto& [type, bytes] : captured_) {
    if (type == command) out.push_back(bytes);
  }
  return out;
}

std::vector<robot::Message> UdpRelay::replies() const {
  std::lock_guard lock(mutex_);
  return replies_;
}

std::vector<UdpRelay::Bytes> UdpRelay::capturedReplies(robot::MessageType reply) const {
  std::lock_guard lock(mutex_);
  std::vector<Bytes> out;
  for (const auto& [type, bytes] : captured_replies_) {
    if (type == reply) out.push_back(bytes);
  }
  return out;
}

void UdpRelay::injectReply(const Bytes& bytes) {
  std::lock_guard lock(mutex_);
  if (client_) front_.sendTo(bytes, *client_);
}

bool UdpRelay::lose(double probability) {
  return probability > 0.0 &&
         std::uniform_real_distribution<double>(0.0, 1.0)(random_) < probability;
}

void UdpRelay::run() {
  std::optional<robot::Endpoint>& client = client_;
  auto last = std::chrono::steady_clock::now();
  while (!stop_) {
    front_.wait(1);
    // How long the relay itself went without a turn (it waits at most 1 ms for datagrams).
    const auto turn = std::chrono::steady_clock::now();
    const auto gap = std::chrono::duration_cast<std::chrono::microseconds>(turn - last).count();
    last = turn;
    if (gap > longest_stall_us_.load()) longest_stall_us_ = gap;
    std::lock_guard lock(mutex_);
    while (auto d = front_.receive()) {
      client = d->from;
      const robot::Decoded decoded = robot::decode(d->bytes.data(), d->bytes.size(), key_);
      if (decoded.ok()) captured_.emplace_back(decoded.message.type, d->bytes);
      if (cut_ || lose(loss_to_backend_)) {
        ++dropped_;
      } else if (decoded.ok() && holding_.count(decoded.message.type)) {
        held_.emplace_back(decoded.message.sequence, d->bytes);
      } else {
        if (decoded.ok() && decoded.message.type == robot::MessageType::Heartbeat &&
            delay_.count() == 0)
          last_heartbeat_us_ = decoded.message.time_us;
        forward(std::move(d->bytes), true);
      }
    }
    while (auto d = back_.receive()) {
      const robot::Decoded decoded = robot::decode(d->bytes.data(), d->bytes.size(), key_);
      if (decoded.ok()) {
        replies_.push_back(decoded.message);
        captured_replies_.emplace_back(decoded.message.type, d->bytes);
      }
      if (!client || cut_ || lose(loss_to_client_) ||
          (decoded.ok() && dropping_.count(decoded.message.type))) {
        ++dropped_;
      } else {
        forward(std::move(d->bytes), false);
      }
    }
    const auto now = std::chrono::steady_clock::now();
    for (const Delayed& d : delayed_) {
      if (d.due > now) continue;
      if (d.to_backend) {
        back_.sendTo(d.bytes, backend_);
      } else if (client) {
        front_.sendTo(d.bytes, *client);
      }
    }
    std::erase_if(delayed_, [&](const Delayed& d) { return d.due <= now; });
  }
}

}  // namespace arbci::test
