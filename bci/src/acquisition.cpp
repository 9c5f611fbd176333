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
    try {
      pump();
    } catch (const std::exception& error) {
      // Never across the thread: the stream stops and the session is told why.
      std::lock_guard lock(state_mutex_);
      fault_ = std::string("EEG acquisition stopped: ") + error.what();
      return;
    }
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
  if (blocks.empty()) return;
  const double now = hostSeconds();
  bool stamped_by_arrival = false;
  ClockModel::Observation newest;
  for (const Block& block : blocks) {
    // Stepped: each block arrives the instant it is complete, as from a perfect amplifier.
    // A source that knows when its samples were taken (LSL) gives the instant the block was
    // complete: one sample period after its last. Otherwise the block is stamped with the instant
    // the delivery arrived (the clock model keeps only the newest block of it).
    double at = now;
    if (mode_ == Mode::Stepped) {
      at = clock_->availableAtHost(block.endSample(), info_.rate_hz);
    } else if (!std::isnan(block.taken_host_s)) {
      at = block.taken_host_s + 1.0 / info_.rate_hz;
    } else {
      stamped_by_arrival = true;
    }
    newest = deliver(block, at);
  }
  if (!stamped_by_arrival) return;
  std::lock_guard lock(state_mutex_);
  const std::int64_t first = blocks.front().first_sample;
  const std::int64_t samples = blocks.back().endSample() - first;
  const bool backlog = samples > ClockModel::kLateLimitS * info_.rate_hz;
  if ((backlog || newest.stall) && last_delivery_host_ > 0.0)
    stalls_.push_back({first, samples, newest.late_s, last_delivery_host_, now});
  last_delivery_host_ = now;
}

ClockModel::Observation Acquisition::deliver(const Block& delivered, double host_s) {
  std::lock_guard lock(state_mutex_);
  if (next_sample_ < 0) next_sample_ = first_sample_ = delivered.first_sample;
  if (delivered.endSample() <= next_sample_) {
    repeated_ += delivered.samples;  // a repeat of samples already delivered
    return {};
  }
  const Block* block = &delivered;
  Block trimmed;
  if (delivered.first_sample < next_sample_) {
    // Overlapping what was delivered: only the new samples go on (the ring takes each sample once).
    const std::int64_t repeat = next_sample_ - delivered.first_sample;
    repeated_ += repeat;
    trimmed = Block(next_sample_, delivered.channels, delivered.samples - static_cast<int>(repeat));
    trimmed.taken_host_s = delivered.taken_host_s;
    for (int c = 0; c < delivered.channels; ++c) {
      for (int i = 0; i < trimmed.samples; ++i)
        trimmed.at(c, i) = delivered.at(c, i + static_cast<int>(repeat));
    }
    block = &trimmed;
  }
  if (block->first_sample > next_sample_) {
    // A gap: zeros in its place, so the stream stays continuous and sample numbers true.
    const std::int64_t missing = block->first_sample - next_sample_;
    losses_.push_back({next_sample_, missing, "gap in the source's samples"});
    lost_ += missing;
    model_.startAgain();
    for (std::int64_t from = next_sample_; from < block->first_sample;) {
      const int n = static_cast<int>(std::min<std::int64_t>(block->first_sample - from, 4096));
      ring_.write(Block(from, block->channels, n));
      from += n;
    }
  }
  ring_.write(*block);
  next_sample_ = block->endSample();
  return model_.observe(block->endSample(), host_s);
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

ClockReport Acquisition::clockReport() const {
  std::lock_guard lock(state_mutex_);
  ClockReport out;
  if (!model_.fitted()) return out;
  out.drift_ppm = model_.driftPpm();
  out.drift_uncertainty_ppm = model_.driftUncertaintyPpm();
  out.jitter_s = model_.jitterS();
  out.drift_reliable = model_.driftReliable();
  out.drift_at_bound = model_.driftAtBound();
  return out;
}

std::vector<DeliveryStall> Acquisition::takeStalls() {
  std::lock_guard lock(state_mutex_);
  return std::exchange(stalls_, {});
}

std::string Acquisition::fault() const {
  std::lock_guard lock(state_mutex_);
  return fault_;
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
