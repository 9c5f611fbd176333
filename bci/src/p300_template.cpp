#include "arbci/bci/p300_template.h"

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "arbci/bci/electrode_positions.h"
#include "arbci/bci/epocher.h"
#include "arbci/bci/filters.h"

namespace arbci::bci {

Eigen::VectorXd p300Template(const PipelineSettings& settings, const SignalInfo& info) {
  static const std::set<std::string> sites = {"PZ", "P3", "P4", "CPZ", "CZ", "POZ", "P1", "P2"};
  const FeatureExtractor extractor(settings, info);
  std::vector<int> parietal;
  for (int c : extractor.channelIndices()) {
    if (sites.count(electrodeKey(info.channels[static_cast<size_t>(c)]))) parietal.push_back(c);
  }
  if (parietal.empty()) return {};
  // One response three seconds in (the filters settled), in five seconds of signal, cut by the
  // online epocher.
  const double rate = info.rate_hz;
  const auto onset = static_cast<std::int64_t>(std::lround(3.0 * rate));
  Block signal(0, info.channelCount(), static_cast<int>(std::lround(5.0 * rate)));
  for (int c : parietal) {
    for (int s = 0; s < signal.samples; ++s) {
      const double t = static_cast<double>(s - onset) / rate - 0.35;
      signal.data[static_cast<size_t>(c) * signal.samples + s] =
          static_cast<float>(std::exp(-0.5 * (t / 0.075) * (t / 0.075)));
    }
  }
  filterWhole(signal, settings.filter, info, settings.zero_phase);
  Epocher epocher(info.channelCount(), rate, settings.window, 5.0);
  StimulusEvent flash;
  flash.sample = onset;
  flash.code = 1;
  flash.target = true;
  epocher.addEvent(flash);
  const std::vector<Epoch> epochs = epocher.push(signal);
  if (epochs.empty()) return {};
  return extractor.features(epochs.front());
}

}  // namespace arbci::bci
