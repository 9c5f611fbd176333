// An arm (the simulated one unless given another driver), noting when it was first halted (a
// STOP or the watchdog): the ground truth for halt latencies in the link tests and the link bench.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>

#include "arbci/robot/simulated_arm.h"

namespace arbci::test {

class HaltRecordingArm : public robot::RobotDriver {
 public:
  using Clock = std::chrono::steady_clock;
  // `halted_at` receives Clock::now().time_since_epoch().count() at the first stop(); 0 until.
  HaltRecordingArm(const robot::RobotConfig& config,
                   std::shared_ptr<std::atomic<Clock::rep>> halted_at)
      : HaltRecordingArm(std::make_unique<robot::SimulatedArm>(config), std::move(halted_at)) {}
  HaltRecordingArm(std::unique_ptr<robot::RobotDriver> arm,
                   std::shared_ptr<std::atomic<Clock::rep>> halted_at)
      : arm_(std::move(arm)), halted_at_(std::move(halted_at)) {}
  std::optional<robot::Rejection> check(const robot::DriverCommand& c) const override {
    return arm_->check(c);
  }
  void start(const robot::DriverCommand& c) override { arm_->start(c); }
  void stop() override {
    Clock::rep none = 0;
    halted_at_->compare_exchange_strong(none, Clock::now().time_since_epoch().count());
    arm_->stop();
  }
  std::optional<robot::DriverResult> step(double seconds) override { return arm_->step(seconds); }
  robot::DriverStatus status() const override { return arm_->status(); }
  std::vector<robot::WorldObject> world() const override { return arm_->world(); }

 private:
  std::unique_ptr<robot::RobotDriver> arm_;
  std::shared_ptr<std::atomic<Clock::rep>> halted_at_;
};

}  // namespace arbci::test
