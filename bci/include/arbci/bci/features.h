// P300 features as BCI2000's P300 classifier computes them: the response window after each
// stimulus (default 0-800 ms), decimated to about 20 Hz by moving average, for the chosen
// channels. A feature vector is channel-major: feature c * bins + b is channel c, bin b.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "arbci/bci/epocher.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/signal.h"

namespace arbci::bci {

// Everything between the raw signal and the classifier; saved with each model so training and
// online use process the signal the same way. Each field's default, range and meaning:
// bci::pipelineSchema() (bci/settings.h).
struct PipelineSettings {
  PipelineSettings();  // the schema's defaults
  FilterSettings filter;
  EpochWindow window;
  double decimate_hz;
  std::vector<std::string> channels;  // empty: all of the recording's
  // Offline only (arbci train/evaluate): the filters run forward and backward, so no phase lag;
  // the model records it, and the online cycle, which must stay causal, says so.
  bool zero_phase;

  int decimationFactor(double rate_hz) const;  // samples per bin: 13 at 256 Hz
};

struct FeatureShape {
  int channels = 0;
  int bins = 0;
  double bin_s = 0.0;  // each bin's duration (0: not known)
  int size() const { return channels * bins; }
};

class FeatureExtractor {
 public:
  // Throws std::invalid_argument naming a requested channel the signal lacks.
  FeatureExtractor(const PipelineSettings& settings, const SignalInfo& info);
  const FeatureShape& shape() const { return shape_; }
  const std::vector<int>& channelIndices() const { return channel_indices_; }
  int factor() const { return factor_; }
  // The features of an epoch cut by an Epocher with the settings' window.
  Eigen::VectorXd features(const Epoch& epoch) const;

 private:
  std::vector<int> channel_indices_;
  int factor_;
  FeatureShape shape_;
};

}  // namespace arbci::bci
