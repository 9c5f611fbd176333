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
      ring_(std::max(1, info_.channelCount()),
            std::max(1, static_cast<int>(settings.queue_s * info_.rate_hz))),
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
    pump();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void Acquisition::advanceTo(double host_s) {
  if (mode_ != Mode::Stepped) return;
  {
    std::lock_guard lock(source_mutex_);
    static_cast<ManualClock&>(*clock_).advanceTo(host_s);
  }
  pump();
}

void Acquisition::pump() {
  std::vector<Block> blocks;
  {
    std::lock_guard lock(source_mutex_);
    blocks = source_->poll(256);
  }
  const double now = hostSeconds();
  for (const Block& block : blocks) {
    // Stepped: each block arrives the instant it is complete, as from a perfect amplifier.
    // A source that knows when its samples were taken (LSL) gives the instant the block was
    // complete: one sample period after its last.
    double at = now;
    if (mode_ == Mode::Stepped)
      at = clock_->availableAtHost(block.endSample(), info_.rate_hz);
    else if (!std::isnan(block.taken_host_s))
      at = block.taken_host_s + 1.0 / info_.rate_hz;
    deliver(block, at);
  }
}

void Acquisition::deliver(const Block& block, double host_s) {
  std::lock_guard lock(state_mutex_);
  if (next_sample_ < 0) next_sample_ = first_sample_ = block.first_sample;
  if (block.endSample() <= next_sample_) return;  // a repeat of samples already delivered
  if (block.first_sample > next_sample_) {
    // A gap: zeros in its place, so the stream stays continuous and sample numbers true.
    const std::int64_t missing = block.first_sample - next_sample_;
    losses_.push_back({next_sample_, missing, "gap in the source's samples"});
    lost_ += missing;
    for (std::int64_t from = next_sample_; from < block.first_sample;) {
      const int n = static_cast<int>(std::min<std::int64_t>(block.first_sample - from, 4096));
      ring_.write(Block(from, block.channels, n));
      from += n;
    }
  }
  ring_.write(block);
  next_sample_ = block.endSample();
  model_.observe(block.endSample(), host_s);
}

std::vector<Block> Acquisition::take() {
  std::vector<Block> out;
  if (!reader_) {
    std::lock_guard lock(state_mutex_);
    if (next_sample_ < 0) return out;  // nothing yet
    reader_.emplace(ring_.reader(first_sample_));
  }
  const std::int64_t position = reader_->position();
  RingBuffer::Read read = reader_->read(1 << 20);
  if (read.lost > 0) {
    // Overwritten before the cycle took it: zeros in its place, counted.
    {
      std::lock_guard lock(state_mutex_);
      losses_.push_back({position, read.lost, "the cycle fell behind (the ring overflowed)"});
    }
    lost_ += read.lost;
    for (std::int64_t from = position; from < position + read.lost;) {
      const int n = static_cast<int>(std::min<std::int64_t>(position + read.lost - from, 4096));
      out.emplace_back(from, read.block.channels, n);
      from += n;
    }
  }
  if (read.block.samples > 0) out.push_back(std::move(read.block));
  return out;
}

std::vector<SampleLoss> Acquisition::takeLosses() {
  std::lock_guard lock(state_mutex_);
  return std::exchange(losses_, {});
}

std::int64_t Acquisition::firstSampleAtOrAfter(double host_s) const {
  return std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(sampleAt(host_s) - 1e-6)));
}

double Acquisition::sampleAt(double host_s) const {
  std::lock_guard lock(state_mutex_);
  // Before the first block, the source's own clock is the best guess.
  if (model_.empty()) return clock_->sampleAtHost(host_s, info_.rate_hz);
  return model_.sampleAt(host_s);
}

double Acquisition::driftPpm() const {
  std::lock_guard lock(state_mutex_);
  return model_.fitted() ? model_.driftPpm() : 0.0;
}

double Acquisition::jitterS() const {
  std::lock_guard lock(state_mutex_);
  return model_.jitterS();
}

void Acquisition::withSource(const std::function<void(EegSource&)>& call) {
  std::lock_guard lock(source_mutex_);
  call(*source_);
}

}  // namespace arbci::bci
