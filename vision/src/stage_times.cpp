#include <algorithm>

#include "arbci/vision/marker.h"

namespace arbci::vision {

StageTimes& StageTimes::operator+=(const StageTimes& more) {
  for (const auto& entry : kStageParts) this->*entry.second += more.*entry.second;
  total += more.total;
  return *this;
}

StageTimes medianRun(std::vector<StageTimes> runs) {
  if (runs.empty()) return {};
  const auto middle = runs.begin() + static_cast<std::ptrdiff_t>(runs.size() / 2);
  std::nth_element(runs.begin(), middle, runs.end(),
                   [](const StageTimes& a, const StageTimes& b) { return a.total < b.total; });
  return *middle;
}

}  // namespace arbci::vision
