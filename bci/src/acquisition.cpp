#include "arbci/bci/acquisition.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace arbci::bci {

Acquisition::Acquisition(std::unique_ptr<EegSource> source, std::shared_ptr<SampleClock> clock,
                         Mode mode, const AcquisitionSettings& settings)
    : source_(std::move(source)),
      clock_(std::move(clock)),
      mode_(mode),
      settings_(settings),
      info_(source_ ? source_->info() : SignalInfo{}),
      model_(info_.rate_hz, settings.clock_window_s,
             settings.latency_s + (source_ ? source_->knownLatencyS() : 0.0)) {
  if (!source_) throw std::invalid_argument("acquisition: no EEG source");
  if (!clock_) throw std::invalid_argument("acquisition: no clock");
  if (mode == Mode::Stepped && !dynamic_cast<ManualClock*>(clock_.get()))
    throw std::invalid_argument("acquisition: a stepped acquisition needs a manual clock");
}

Acquisition::~Acquisition() {
  stop();
}

void Acquisition::start() {
  if (mode_ != Mode::Live || running_.exchange(true)) return;
  thread_ = std::thread([this] { loop(); });
}

void Acquisition::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void Acquisition::loop() {
  while (running_) {
    pump(false);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void Acquisition::advanceTo(double host_s) {
  if (mode_ != Mode::Stepped) return;
  {
    std::lock_guard lock(source_mutex_);
    static_cast<ManualClock&>(*clock_).advanceTo(host_s);
  }
  pump(true);
}

void Acquisition::pump(bool stepped) {
  std::vector<Block> blocks;
  {
    std::lock_guard lock(source_mutex_);
    blocks = source_->poll(256);
  }
  const double now = stepped ? 0.0 : hostSeconds();
  for (Block& block : blocks) {
    // Stepped: each block arrives the instant it is complete, as from a perfect amplifier.
    const double arrived =
        stepped ? clock_->availableAtHost(block.endSample(), info_.rate_hz) : now;
    deliver(std::move(block), arrived);
  }
}

void Acquisition::deliver(Block block, double host_s) {
  std::lock_guard lock(queue_mutex_);
  if (next_sample_ < 0) next_sample_ = taken_end_ = block.first_sample;
  if (block.endSample() <= next_sample_) return;  // a repeat of samples already delivered
  if (block.first_sample > next_sample_) {
    const std::int64_t missing = block.first_sample - next_sample_;
    losses_.push_back({next_sample_, missing, "gap in the source's samples"});
    lost_ += missing;
  }
  next_sample_ = block.endSample();
  model_.observe(block.endSample(), host_s);
  arrived_ += block.samples;
  queued_samples_ += block.samples;
  queue_.push_back(std::move(block));
  // The cycle has not taken its blocks for longer than the queue holds: the oldest are lost.
  const auto capacity = static_cast<std::int64_t>(settings_.queue_s * info_.rate_hz);
  while (queued_samples_ > capacity && queue_.size() > 1) {
    const Block& oldest = queue_.front();
    losses_.push_back({oldest.first_sample, oldest.samples, "the cycle fell behind (queue full)"});
    lost_ += oldest.samples;
    queued_samples_ -= oldest.samples;
    queue_.pop_front();
  }
}

std::vector<Block> Acquisition::take() {
  std::lock_guard lock(queue_mutex_);
  std::vector<Block> out;
  out.reserve(queue_.size());
  for (Block& block : queue_) {
    // A lost stretch (gap or overflow) is zeros in the stream, so sample numbers stay true.
    if (block.first_sample > taken_end_) {
      for (std::int64_t from = taken_end_; from < block.first_sample;) {
        const int n = static_cast<int>(std::min<std::int64_t>(block.first_sample - from, 4096));
        out.emplace_back(from, block.channels, n);
        from += n;
      }
    }
    taken_end_ = block.endSample();
    out.push_back(std::move(block));
  }
  queue_.clear();
  queued_samples_ = 0;
  return out;
}

std::vector<SampleLoss> Acquisition::takeLosses() {
  std::lock_guard lock(queue_mutex_);
  return std::exchange(losses_, {});
}

std::int64_t Acquisition::firstSampleAtOrAfter(double host_s) const {
  return std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(sampleAt(host_s) - 1e-6)));
}

double Acquisition::sampleAt(double host_s) const {
  std::lock_guard lock(queue_mutex_);
  // Before the first block, the source's own clock is the best guess.
  if (model_.empty()) return clock_->sampleAtHost(host_s, info_.rate_hz);
  return model_.sampleAt(host_s);
}

double Acquisition::driftPpm() const {
  std::lock_guard lock(queue_mutex_);
  return model_.fitted() ? model_.driftPpm() : 0.0;
}

double Acquisition::jitterS() const {
  std::lock_guard lock(queue_mutex_);
  return model_.jitterS();
}

bool Acquisition::clockFitted() const {
  std::lock_guard lock(queue_mutex_);
  return model_.fitted();
}

void Acquisition::withSource(const std::function<void(EegSource&)>& call) {
  std::lock_guard lock(source_mutex_);
  call(*source_);
}

}  // namespace arbci::bci
