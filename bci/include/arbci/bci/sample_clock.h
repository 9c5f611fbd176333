// How many samples a source may have delivered by now: paced by the wall clock, set by the caller
// (the headless session's simulated clock), or unbounded (as fast as the consumer reads). A clock
// also says which sample a source takes at a given host instant, so a simulated amplifier can put
// what the screen showed (its virtual photodiode) on the right sample, as a real one would.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>

namespace arbci::bci {

// The host clock every live timestamp uses: seconds of std::chrono::steady_clock.
inline double hostSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class SampleClock {
 public:
  virtual ~SampleClock() = default;
  // Samples available since the start, at `rate_hz`.
  virtual std::int64_t available(double rate_hz) const = 0;
  // The (fractional) sample the source takes at host instant `host_s`.
  virtual double sampleAtHost(double host_s, double rate_hz) const = 0;
  // The host instant at which a block ending at `end_sample` becomes available.
  virtual double availableAtHost(std::int64_t end_sample, double rate_hz) const = 0;
  // How long after its last sample's period a block is delivered (a simulated transport delay).
  virtual double deliveryLagS() const { return 0.0; }
};

// Real time from construction; `lag_s` holds every block back as an amplifier's buffer would.
class WallClock final : public SampleClock {
 public:
  explicit WallClock(double lag_s = 0.0) : start_(hostSeconds()), lag_(lag_s) {}
  std::int64_t available(double rate_hz) const override {
    const double samples = (hostSeconds() - start_ - lag_) * rate_hz;
    return samples > 0.0 ? static_cast<std::int64_t>(samples) : 0;
  }
  double sampleAtHost(double host_s, double rate_hz) const override {
    return (host_s - start_) * rate_hz;
  }
  double availableAtHost(std::int64_t end_sample, double rate_hz) const override {
    return start_ + lag_ + static_cast<double>(end_sample) / rate_hz;
  }
  double deliveryLagS() const override { return lag_; }

 private:
  double start_, lag_;
};

// Advanced by the caller, in seconds of simulated time (which is then also the host time).
class ManualClock final : public SampleClock {
 public:
  void advanceTo(double seconds) { seconds_ = seconds; }
  double seconds() const { return seconds_; }
  std::int64_t available(double rate_hz) const override {
    return static_cast<std::int64_t>(seconds_ * rate_hz + 1e-9);
  }
  double sampleAtHost(double host_s, double rate_hz) const override { return host_s * rate_hz; }
  double availableAtHost(std::int64_t end_sample, double rate_hz) const override {
    return static_cast<double>(end_sample) / rate_hz;
  }

 private:
  double seconds_ = 0.0;
};

class UnboundedClock final : public SampleClock {
 public:
  std::int64_t available(double) const override { return std::numeric_limits<std::int64_t>::max(); }
  double sampleAtHost(double host_s, double rate_hz) const override { return host_s * rate_hz; }
  double availableAtHost(std::int64_t, double) const override { return 0.0; }
};

}  // namespace arbci::bci
