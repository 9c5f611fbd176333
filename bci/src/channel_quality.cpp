#include "arbci/bci/channel_quality.h"

#include <algorithm>
#include <cmath>

#include "arbci/bci/intervals.h"
#include "arbci/bci/signal.h"

namespace arbci::bci {

std::vector<ChannelQuality> assessChannels(const Recording& r) {
  std::vector<ChannelQuality> out;
  int channels = r.info.channelCount();
  if (r.samples < 2) return out;
  // A session's photodiode channel is no EEG (the dataset leaves it out too).
  const auto photodiode = r.parameters.find("PhotodiodeChannel");
  for (int c = 0; c < r.info.channelCount(); ++c) {
    if (photodiode != r.parameters.end() &&
        r.info.channels[static_cast<size_t>(c)] == photodiode->second) {
      --channels;
      continue;
    }
    const float* x = r.data.data() + static_cast<std::ptrdiff_t>(c) * r.samples;
    double mean = 0.0;
    for (std::int64_t s = 0; s < r.samples; ++s) mean += x[s];
    mean /= static_cast<double>(r.samples);
    double variance = 0.0;
    for (std::int64_t s = 0; s < r.samples; ++s) variance += (x[s] - mean) * (x[s] - mean);
    out.push_back({r.info.channels[static_cast<size_t>(c)],
                   std::sqrt(variance / static_cast<double>(r.samples - 1))});
  }
  std::vector<double> sds;
  for (const ChannelQuality& q : out) sds.push_back(q.sd_uv);
  const double typical = median(sds);
  for (ChannelQuality& q : out) {
    q.flat = q.sd_uv < kFlatSdUv;
    q.drifting = channels >= 3 && typical > 0.0 && q.sd_uv > 20.0 * typical;
  }
  return out;
}

Recording withoutChannels(const Recording& recording, const std::vector<std::string>& channels) {
  Recording out = recording;
  for (const std::string& name : channels) {
    const auto found = std::find(out.info.channels.begin(), out.info.channels.end(), name);
    if (found == out.info.channels.end()) continue;
    const int index = static_cast<int>(found - out.info.channels.begin());
    out.data =
        withoutChannel(out.data, out.info.channelCount(), static_cast<int>(out.samples), index);
    out.info.channels.erase(found);
  }
  return out;
}

}  // namespace arbci::bci
