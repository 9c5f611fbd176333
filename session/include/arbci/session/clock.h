// The session's one time base, in two modes, so no stage asks "simulated?":
//  - Stepped: a simulated clock that advances one display frame per cycle as fast as the machine
//    allows; the EEG source, the arm and the cameras all follow it, so a seed gives the same run
//    byte for byte. Work off the cycle's thread (training) is waited for, on the same frame every
//    run.
//  - RealTime: the host clock (bci::hostSeconds()). Sources run on their own clocks; the EEG
//    source's samples are mapped to host instants by the acquisition's clock model, which the
//    acquisition stage lends the clock (sampleAt), so any stage can stamp an instant with the EEG
//    sample taken then. Work off the thread is looked at, never waited for.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>

#include "arbci/bci/sample_clock.h"

namespace arbci::session {

class Clock {
 public:
  enum class Mode { Stepped, RealTime };
  Clock(Mode mode, double display_hz);

  Mode mode() const { return mode_; }
  bool stepped() const { return mode_ == Mode::Stepped; }
  double displayHz() const { return display_hz_; }
  double framePeriodS() const { return 1.0 / display_hz_; }

  // Session second 0 is now (RealTime: on the host clock; Stepped: host instant 0).
  void start();
  // Frame `frame`'s session time: Stepped, frame / display_hz; RealTime, the host clock now.
  double frameTime(std::int64_t frame) const;
  // Session seconds on the host clock and back.
  double hostOf(double session_s) const { return origin_ + session_s; }
  double sessionOf(double host_s) const { return host_s - origin_; }
  // A presentation instant for a display without a swap of its own (headless): Stepped, the
  // frame's own time; RealTime, the host clock now.
  double presentedNow(double frame_time_s) const;
  // Headless real time: sleeps until frame `next_frame` is due (Stepped: returns at once).
  void pace(std::int64_t next_frame) const;

  // The clock that paces an EEG source: Stepped, a manual clock the acquisition advances to each
  // cycle's time; RealTime, the wall clock holding each block back `lag_s` (a simulated USB
  // transport).
  std::shared_ptr<bci::SampleClock> sourceClock(double lag_s) const;

  // Work done off the cycle's thread: Stepped waits for it; RealTime says whether it is done.
  template <class T>
  bool ready(const std::future<T>& work) const {
    if (!work.valid()) return false;
    if (stepped()) {
      work.wait();
      return true;
    }
    return work.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  }

  // The EEG sample clock: the first sample taken at or after host instant `host_s`, and the
  // (fractional) sample taken at it. Until the acquisition stage lends its clock model, every
  // instant is sample 0.
  void setSampleMap(std::function<std::int64_t(double host_s)> first_at_or_after,
                    std::function<double(double host_s)> at) {
    first_sample_ = std::move(first_at_or_after);
    sample_ = std::move(at);
  }
  std::int64_t sampleAt(double host_s) const { return first_sample_ ? first_sample_(host_s) : 0; }
  double fractionalSampleAt(double host_s) const { return sample_ ? sample_(host_s) : 0.0; }

 private:
  Mode mode_;
  double display_hz_;
  double origin_ = 0.0;
  std::function<std::int64_t(double)> first_sample_;
  std::function<double(double)> sample_;
};

}  // namespace arbci::session
