#include "arbci/session/clock.h"

#include <thread>

namespace arbci::session {

Clock::Clock(Mode mode, double display_hz) : mode_(mode), display_hz_(display_hz) {}

void Clock::start() {
  origin_ = stepped() ? 0.0 : bci::hostSeconds();
}

double Clock::frameTime(std::int64_t frame) const {
  return stepped() ? static_cast<double>(frame) / display_hz_ : bci::hostSeconds() - origin_;
}

double Clock::presentedNow(double frame_time_s) const {
  return stepped() ? frame_time_s : bci::hostSeconds();
}

void Clock::pace(std::int64_t next_frame) const {
  if (stepped()) return;
  const double wait = origin_ + static_cast<double>(next_frame) / display_hz_ - bci::hostSeconds();
  if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
}

std::shared_ptr<bci::SampleClock> Clock::sourceClock(double lag_s) const {
  if (stepped()) return std::make_shared<bci::ManualClock>();
  return std::make_shared<bci::WallClock>(lag_s);
}

}  // namespace arbci::session
