#include "arbci/bci/features.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace arbci::bci {

int PipelineSettings::decimationFactor(double rate_hz) const {
  if (!(decimate_hz > 0.0))
    throw std::invalid_argument(
        "decimate_hz 0 stands for the method's own rate: the pipeline was not resolved for a "
        "method (bci::withMethodRate) before its features were taken");
  return std::max(1, static_cast<int>(std::lround(rate_hz / decimate_hz)));
}

FeatureExtractor::FeatureExtractor(const PipelineSettings& settings, const SignalInfo& info)
    : factor_(settings.decimationFactor(info.rate_hz)) {
  if (settings.decimate_hz > info.rate_hz) {
    std::ostringstream message;
    message << "decimate_hz " << settings.decimate_hz << " Hz exceeds the signal's rate "
            << info.rate_hz << " Hz: decimation can only lower the rate";
    throw std::invalid_argument(message.str());
  }
  if (settings.channels.empty()) {
    for (int c = 0; c < info.channelCount(); ++c) channel_indices_.push_back(c);
  } else {
    for (const std::string& name : settings.channels) {
      const auto found = std::find(info.channels.begin(), info.channels.end(), name);
      if (found == info.channels.end())
        throw std::invalid_argument("the signal has no channel " + name);
      channel_indices_.push_back(static_cast<int>(found - info.channels.begin()));
    }
  }
  const int samples = static_cast<int>(
      std::lround((settings.window.end_s - settings.window.start_s) * info.rate_hz));
  shape_.channels = static_cast<int>(channel_indices_.size());
  shape_.bins = samples / factor_;
  shape_.bin_s = factor_ / info.rate_hz;
  if (shape_.bins < 1)
    throw std::invalid_argument("the response window is shorter than one decimation bin");
}

Eigen::VectorXd FeatureExtractor::features(const Epoch& epoch) const {
  Eigen::VectorXd x(shape_.size());
  for (int i = 0; i < shape_.channels; ++i) {
    const int c = channel_indices_[static_cast<size_t>(i)];
    for (int b = 0; b < shape_.bins; ++b) {
      double sum = 0.0;
      for (int s = b * factor_; s < (b + 1) * factor_; ++s) sum += epoch.at(c, s);
      x[i * shape_.bins + b] = sum / factor_;
    }
  }
  return x;
}

}  // namespace arbci::bci
