// Times each stage of the cycle, keeps every cycle's compute time, and counts overruns: cycles
// whose compute time exceeds the block budget (15 samples at 256 Hz: 58.6 ms).
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace arbci::session {

struct Percentiles {
  double p50 = 0, p90 = 0, p95 = 0, p99 = 0, max = 0, mean = 0;
};
// Of `values` (all zeros when there are none).
Percentiles percentiles(std::vector<double> values);

class CycleTiming {
 public:
  explicit CycleTiming(double budget_ms) : budget_ms_(budget_ms) {}

  void beginCycle();
  // Ends the stage that began at the last call (or at beginCycle) and names it.
  void mark(const std::string& stage);
  // Ends the cycle; returns its compute time in milliseconds.
  double endCycle();

  double budgetMs() const { return budget_ms_; }
  int overruns() const { return overruns_; }
  size_t cycles() const { return total_.size(); }
  const std::map<std::string, double>& lastCycle() const { return last_; }
  double lastTotalMs() const { return total_.empty() ? 0.0 : total_.back(); }
  std::map<std::string, Percentiles> stagePercentiles() const;
  Percentiles totalPercentiles() const { return percentiles(total_); }
  nlohmann::json toJson() const;

 private:
  using Clock = std::chrono::steady_clock;
  double budget_ms_;
  Clock::time_point cycle_start_, stage_start_;
  std::map<std::string, double> current_, last_;
  std::map<std::string, std::vector<double>> stages_;
  std::vector<double> total_;
  int overruns_ = 0;
};

}  // namespace arbci::session
