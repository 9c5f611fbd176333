#include "arbci/session/cycle_timing.h"

#include <algorithm>
#include <numeric>

namespace arbci::session {

Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    return v[std::min(v.size() - 1,
                      static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
  };
  p.p50 = at(0.5);
  p.p90 = at(0.9);
  p.p95 = at(0.95);
  p.p99 = at(0.99);
  p.max = v.back();
  p.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  return p;
}

void CycleTiming::beginCycle() {
  cycle_start_ = stage_start_ = Clock::now();
  current_.clear();
}

void CycleTiming::mark(const std::string& stage) {
  const auto now = Clock::now();
  current_[stage] += std::chrono::duration<double, std::milli>(now - stage_start_).count();
  stage_start_ = now;
}

double CycleTiming::endCycle() {
  const double total =
      std::chrono::duration<double, std::milli>(Clock::now() - cycle_start_).count();
  for (const auto& [stage, ms] : current_) stages_[stage].push_back(ms);
  total_.push_back(total);
  if (total > budget_ms_) ++overruns_;
  last_ = current_;
  return total;
}

std::map<std::string, Percentiles> CycleTiming::stagePercentiles() const {
  std::map<std::string, Percentiles> out;
  for (const auto& [stage, values] : stages_) out[stage] = percentiles(values);
  return out;
}

nlohmann::json CycleTiming::toJson() const {
  auto json = [](const Percentiles& p) {
    return nlohmann::json{{"p50_ms", p.p50},
                          {"p90_ms", p.p90},
                          {"p99_ms", p.p99},
                          {"max_ms", p.max},
                          {"mean_ms", p.mean}};
  };
  nlohmann::json out = {{"cycles", total_.size()},
                        {"budget_ms", budget_ms_},
                        {"overruns", overruns_},
                        {"total", json(totalPercentiles())}};
  for (const auto& [stage, p] : stagePercentiles()) out["stages"][stage] = json(p);
  return out;
}

}  // namespace arbci::session
