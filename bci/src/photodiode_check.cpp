#include "arbci/bci/photodiode_check.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arbci::bci {

namespace {

// Pairs each recorded onset with the nearest unused edge within `max_offset_s`.
void pairEdges(const Recording& recording, const std::vector<std::int64_t>& edges,
               double max_offset_s, PhotodiodeReport& r) {
  r.edges = static_cast<int>(edges.size());
  std::vector<std::int64_t> onsets;
  for (const StimulusEvent& e : recording.stimuli) onsets.push_back(e.sample);
  std::sort(onsets.begin(), onsets.end());
  r.flashes = static_cast<int>(onsets.size());
  const double max_samples = max_offset_s * r.rate_hz;
  std::vector<bool> edge_used(edges.size(), false);
  for (std::int64_t onset : onsets) {
    const auto after = std::lower_bound(edges.begin(), edges.end(), onset);
    std::ptrdiff_t best = -1;
    for (auto it : {after - 1, after}) {
      if (it < edges.begin() || it >= edges.end()) continue;
      const auto i = it - edges.begin();
      if (edge_used[static_cast<size_t>(i)] || std::abs(*it - onset) > max_samples) continue;
      if (best < 0 || std::abs(*it - onset) < std::abs(edges[static_cast<size_t>(best)] - onset))
        best = i;
    }
    if (best < 0) {
      ++r.unmatched_flashes;
      r.unmatched_onsets.push_back(onset);
      continue;
    }
    r.paired_onsets.push_back(onset);
    edge_used[static_cast<size_t>(best)] = true;
    r.offsets_ms.push_back(1000.0 * static_cast<double>(edges[static_cast<size_t>(best)] - onset) /
                           r.rate_hz);
  }
  r.count = static_cast<int>(r.offsets_ms.size());
  r.unmatched_edges = r.edges - r.count;
  if (r.count > 0) {
    double sum = 0.0, squares = 0.0;
    for (double o : r.offsets_ms) sum += o;
    r.mean_ms = sum / r.count;
    for (double o : r.offsets_ms) squares += (o - r.mean_ms) * (o - r.mean_ms);
    r.sd_ms = r.count > 1 ? std::sqrt(squares / (r.count - 1)) : 0.0;
    const auto [lo, hi] = std::minmax_element(r.offsets_ms.begin(), r.offsets_ms.end());
    r.min_ms = *lo;
    r.max_ms = *hi;
  }
}

}  // namespace

PhotodiodeReport checkPhotodiode(const Recording& recording, const std::string& channel,
                                 double max_offset_s) {
  const auto found =
      std::find(recording.info.channels.begin(), recording.info.channels.end(), channel);
  if (found == recording.info.channels.end())
    throw std::invalid_argument(recording.source + ": no photodiode channel \"" + channel + "\"");
  const int c = static_cast<int>(found - recording.info.channels.begin());
  PhotodiodeReport r;
  r.channel = channel;
  r.rate_hz = recording.info.rate_hz;
  float low = 0.0f, high = 0.0f;
  if (recording.samples > 0) {
    const auto begin = recording.data.begin() + static_cast<std::ptrdiff_t>(c) * recording.samples;
    const auto [lo, hi] = std::minmax_element(begin, begin + recording.samples);
    low = *lo;
    high = *hi;
  }
  if (!(high > low))
    throw std::invalid_argument(recording.source + ": the photodiode channel \"" + channel +
                                "\" never changes (is the diode on the patch?)");
  r.threshold = 0.5 * (low + high);
  std::vector<std::int64_t> edges;
  for (std::int64_t s = 1; s < recording.samples; ++s) {
    if (recording.at(c, s - 1) <= r.threshold && recording.at(c, s) > r.threshold)
      edges.push_back(s);
  }
  pairEdges(recording, edges, max_offset_s, r);
  return r;
}

PhotodiodeReport checkPhotodiodeMarkers(const Recording& recording, const std::string& marker,
                                        double max_offset_s) {
  PhotodiodeReport r;
  r.channel = "marker " + marker;
  r.rate_hz = recording.info.rate_hz;
  std::vector<std::int64_t> edges;
  for (const Annotation& a : recording.annotations)
    if (a.text == marker) edges.push_back(a.sample);
  if (edges.empty())
    throw std::invalid_argument(recording.source + ": no marker \"" + marker +
                                "\" (is the photodiode on the trigger input, and the marker's "
                                "name as the amplifier records it?)");
  std::sort(edges.begin(), edges.end());
  pairEdges(recording, edges, max_offset_s, r);
  return r;
}

}  // namespace arbci::bci
