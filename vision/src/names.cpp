// Names of the tracker's enumerations, as used in configuration files and on the command line.
#include <stdexcept>

#include "arbci/vision/marker.h"
#include "arbci/vision/settings.h"
#include "arbci/vision/threshold.h"

namespace arbci::vision {

std::string toString(ThresholdMode mode) {
  switch (mode) {
    case ThresholdMode::Constant:
      return "constant";
    case ThresholdMode::AutoMedian:
      return "auto-median";
    case ThresholdMode::AutoMidrange:
      return "auto-midrange";
    case ThresholdMode::Adaptive:
      return "adaptive";
  }
  return "unknown";
}

ThresholdMode thresholdModeFromString(const std::string& text) {
  for (ThresholdMode mode : {ThresholdMode::Constant, ThresholdMode::AutoMedian,
                             ThresholdMode::AutoMidrange, ThresholdMode::Adaptive}) {
    if (toString(mode) == text) return mode;
  }
  throw std::invalid_argument("unknown threshold mode '" + text +
                              "' (constant, auto-median, auto-midrange, adaptive)");
}

}  // namespace arbci::vision
