// How many samples a source may have delivered by now: paced by the wall clock, set by the caller
// (the headless session's simulated clock), or unbounded (as fast as the consumer reads).
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>

namespace arbci::bci {

class SampleClock {
 public:
  virtual ~SampleClock() = default;
  // Samples available since the start, at `rate_hz`.
  virtual std::int64_t available(double rate_hz) const = 0;
};

class WallClock final : public SampleClock {
 public:
  WallClock() : start_(std::chrono::steady_clock::now()) {}
  std::int64_t available(double rate_hz) const override {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    return static_cast<std::int64_t>(seconds * rate_hz);
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Advanced by the caller, in seconds of simulated time.
class ManualClock final : public SampleClock {
 public:
  void advanceTo(double seconds) { seconds_ = seconds; }
  double seconds() const { return seconds_; }
  std::int64_t available(double rate_hz) const override {
    return static_cast<std::int64_t>(seconds_ * rate_hz + 1e-9);
  }

 private:
  double seconds_ = 0.0;
};

class UnboundedClock final : public SampleClock {
 public:
  std::int64_t available(double) const override { return std::numeric_limits<std::int64_t>::max(); }
};

}  // namespace arbci::bci
