#include "arbci/bci/p300_dataset.h"

#include "arbci/bci/channel_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace arbci::bci {
namespace {

// `length` samples of every channel of `signal` from `first`, channel-major.
std::vector<float> span(const Block& signal, std::int64_t first, int length) {
  std::vector<float> out(static_cast<size_t>(signal.channels) * length);
  for (int c = 0; c < signal.channels; ++c) {
    std::copy_n(signal.data.begin() + static_cast<std::ptrdiff_t>(c * signal.samples + first),
                length, out.begin() + static_cast<std::ptrdiff_t>(c) * length);
  }
  return out;
}

// The largest peak-to-peak amplitude of `channels` in the epoch.
double peakToPeak(const Epoch& epoch, const std::vector<int>& channels) {
  double largest = 0.0;
  for (int c : channels) {
    float low = epoch.at(c, 0), high = low;
    for (int s = 1; s < epoch.samples; ++s) {
      low = std::min(low, epoch.at(c, s));
      high = std::max(high, epoch.at(c, s));
    }
    largest = std::max(largest, static_cast<double>(high - low));
  }
  return largest;
}

// BCI2000 matrix parameters: "matrix R C v..." where R or C may be "{ labels }".
std::vector<std::vector<std::string>> bci2000Matrix(const Recording& r, const std::string& name) {
  const auto found = r.parameters.find(name);
  if (found == r.parameters.end()) return {};
  std::istringstream in(found->second);
  std::string type;
  in >> type;
  auto dimension = [&]() {
    std::string token;
    in >> token;
    if (token != "{") return std::atoi(token.c_str());
    int count = 0;
    while (in >> token && token != "}") ++count;
    return count;
  };
  const int rows = dimension(), columns = dimension();
  std::vector<std::vector<std::string>> matrix(static_cast<size_t>(std::max(rows, 0)));
  for (auto& row : matrix) {
    for (int c = 0; c < columns; ++c) {
      std::string value;
      if (!(in >> value)) return {};
      row.push_back(value);
    }
  }
  return matrix;
}

// A session's photodiode channel (named by its PhotodiodeChannel parameter) is recorded for the
// timing check and never classified: the recording without it, or nothing when it has none.
std::optional<Recording> withoutPhotodiode(const Recording& r) {
  const auto named = r.parameters.find("PhotodiodeChannel");
  if (named == r.parameters.end() || named->second.empty()) return std::nullopt;
  const auto& channels = r.info.channels;
  if (std::find(channels.begin(), channels.end(), named->second) == channels.end())
    return std::nullopt;
  return withoutChannels(r, {named->second});
}

double medianGap(const std::vector<StimulusEvent>& stimuli, double rate) {
  std::vector<double> gaps;
  for (size_t i = 1; i < stimuli.size(); ++i)
    gaps.push_back((stimuli[i].sample - stimuli[i - 1].sample) / rate);
  if (gaps.empty()) return 0.18;
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2),
                   gaps.end());
  return gaps[gaps.size() / 2];
}

}  // namespace

ParadigmLayout layoutOf(const Recording& r) {
  const double soa = medianGap(r.stimuli, r.info.rate_hz);
  if (r.parameters.count("NumMatrixRows") && r.parameters.count("NumMatrixColumns")) {
    const int rows = static_cast<int>(bci2000Number(r, "NumMatrixRows"));
    const int columns = static_cast<int>(bci2000Number(r, "NumMatrixColumns"));
    ParadigmLayout layout = ParadigmLayout::matrix(rows, columns, soa);
    for (const auto& row : bci2000Matrix(r, "TargetDefinitions")) {
      if (!row.empty()) layout.symbols.push_back(row[0] == "%" ? "" : row[0]);
    }
    if (static_cast<int>(layout.symbols.size()) != rows * columns) layout.symbols.clear();
    return layout;
  }
  const auto paradigm = r.parameters.find("Paradigm");
  if (paradigm != r.parameters.end()) {
    int rows = 0, columns = 0, stimuli = 0;
    if (std::sscanf(paradigm->second.c_str(), "row/column %dx%d", &rows, &columns) == 2)
      return ParadigmLayout::matrix(rows, columns, soa);
    if (std::sscanf(paradigm->second.c_str(), "single stimulus, %d", &stimuli) == 1)
      return ParadigmLayout::single(stimuli, soa);
  }
  int highest = 0;
  for (const StimulusEvent& e : r.stimuli) highest = std::max(highest, e.code);
  return ParadigmLayout::single(std::max(highest, 2), soa);
}

std::vector<std::pair<std::string, std::string>> layoutParameters(const Recording& r) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const char* name : {"Paradigm", "GridCodes", "NumMatrixRows", "NumMatrixColumns",
                           "TargetDefinitions", "PhotodiodeChannel"}) {
    if (const auto found = r.parameters.find(name); found != r.parameters.end())
      out.emplace_back(found->first, found->second);
  }
  return out;
}

// The flashes of runs (as buildDataset groups them) that a session annotated as interrupted
// after them: "Calibration selection N interrupted ..." lies between a run's last flash and the
// next run's first.
static std::vector<bool> interruptedFlashes(const Recording& r, const ParadigmLayout& layout,
                                            double gap_limit) {
  std::vector<std::int64_t> marks;
  for (const Annotation& a : r.annotations) {
    if (a.text.rfind("Calibration selection ", 0) == 0 &&
        a.text.find(" interrupted") != std::string::npos)
      marks.push_back(a.sample);
  }
  std::vector<bool> out(r.stimuli.size(), false);
  if (marks.empty()) return out;
  std::vector<size_t> run;  // the current run's flashes
  auto close = [&](std::int64_t next_first) {
    if (run.empty()) return;
    const std::int64_t last = r.stimuli[run.back()].sample;
    for (std::int64_t m : marks) {
      if (m > last && m <= next_first) {
        for (size_t k : run) out[k] = true;
        break;
      }
    }
    run.clear();
  };
  std::int64_t previous = -1;
  for (size_t i = 0; i < r.stimuli.size(); ++i) {
    const StimulusEvent& e = r.stimuli[i];
    if (!e.known || e.code > layout.codes()) continue;
    if (previous >= 0 && e.sample - previous > gap_limit) close(e.sample);
    run.push_back(i);
    previous = e.sample;
  }
  close(std::numeric_limits<std::int64_t>::max());
  return out;
}

P300Dataset buildDataset(const std::vector<Recording>& given, const PipelineSettings& settings,
                         const Progress& progress, const DatasetOptions& options) {
  const double reject_uv = options.reject_uv;
  // A second, zero-phase pass for the figures only where the features' own is causal.
  const bool erp_own_pass =
      options.erp_filter == DatasetOptions::ErpFilter::ZeroPhase && !settings.zero_phase;
  if (given.empty()) throw std::invalid_argument("no recordings given");
  std::vector<Recording> eeg_only;  // copies, only of recordings that carry a photodiode
  std::vector<const Recording*> chosen;
  eeg_only.reserve(given.size());
  for (const Recording& r : given) {
    if (auto stripped = withoutPhotodiode(r)) {
      eeg_only.push_back(std::move(*stripped));
      chosen.push_back(&eeg_only.back());
    } else {
      chosen.push_back(&r);
    }
  }
  auto recording = [&](size_t f) -> const Recording& { return *chosen[f]; };
  const size_t count = given.size();
  P300Dataset data;
  data.info = recording(0).info;
  data.layout = layoutOf(recording(0));
  const FeatureExtractor extractor(settings, data.info);
  data.shape = extractor.shape();
  for (int c : extractor.channelIndices())
    data.feature_channels.push_back(data.info.channels[static_cast<size_t>(c)]);
  const Epocher window_shape(data.info.channelCount(), data.info.rate_hz, settings.window);
  const int offset = window_shape.offsetSamples(), length = window_shape.samplesPerEpoch();

  std::vector<Eigen::VectorXd> rows;
  // ERPs: a 100 ms baseline before the stimulus, to the end of the analysis window.
  const int erp_baseline = std::max(1, static_cast<int>(std::lround(0.1 * data.info.rate_hz)));
  const int erp_length = erp_baseline + offset + length;
  ErpAccumulator erps(data.info.channelCount(), erp_length, erp_baseline);
  for (size_t f = 0; f < count; ++f) {
    const Recording& r = recording(f);
    if (progress) progress(static_cast<double>(f) / count, "filtering and epoching " + r.source);
    if (r.stimuli.empty())
      throw std::invalid_argument(r.source + ": no stimulus events (StimulusCode) to classify");
    if (r.info.rate_hz != data.info.rate_hz) {
      throw std::invalid_argument(r.source + ": sampled at " + std::to_string(r.info.rate_hz) +
                                  " Hz, the first file at " + std::to_string(data.info.rate_hz) +
                                  " Hz");
    }
    if (r.info.channels != data.info.channels)
      throw std::invalid_argument(r.source + ": has other channels than the first file");
    const ParadigmLayout layout = layoutOf(r);
    if (layout.kind != data.layout.kind || layout.codes() != data.layout.codes()) {
      throw std::invalid_argument(r.source + ": " + layout.describeShape() + ", the first file " +
                                  data.layout.describeShape());
    }
    data.sources.push_back(r.source);

    // The whole signal through the online filter chain (block-wise and whole are identical).
    Block signal(0, r.info.channelCount(), static_cast<int>(r.samples));
    signal.data = r.data;
    filterWhole(signal, settings.filter, r.info, settings.zero_phase);
    Block erp_signal;
    if (erp_own_pass) {
      erp_signal = Block(0, r.info.channelCount(), static_cast<int>(r.samples));
      erp_signal.data = r.data;
      filterWhole(erp_signal, settings.filter, r.info, true);
    }
    const Block& erp_source = erp_own_pass ? erp_signal : signal;

    // Selections: runs of flashes separated by pauses longer than four stimulus intervals.
    const double gap_limit = std::max(1.0, 4.0 * layout.soa_s) * r.info.rate_hz;
    const std::vector<bool> interrupted = interruptedFlashes(r, layout, gap_limit);
    std::int64_t previous = -1;
    int in_selection = 0;
    for (size_t i = 0; i < r.stimuli.size(); ++i) {
      const StimulusEvent& e = r.stimuli[i];
      if (interrupted[i]) {
        ++data.interrupted_flashes;
        continue;
      }
      if (!e.known && !options.keep_unknown) {  // a free choice online: no label to learn from
        ++data.unknown_flashes;
        continue;
      }
      if (e.code > layout.codes()) {  // another paradigm's (a session's grid flashes, 101 on)
        ++data.other_code_flashes;
        continue;
      }
      const bool marked_start =
          !options.selection_starts.empty() &&
          std::upper_bound(options.selection_starts.begin(), options.selection_starts.end(),
                           previous) != std::upper_bound(options.selection_starts.begin(),
                                                         options.selection_starts.end(), e.sample);
      const bool new_selection =
          options.selection_starts.empty() ? e.sample - previous > gap_limit : marked_start;
      if (previous < 0 || new_selection) {
        data.selections.push_back(SelectionEpochs{{}, {}, static_cast<int>(f)});
        in_selection = 0;
      }
      previous = e.sample;
      const std::int64_t first = e.sample + offset;
      if (first < 0 || first + length > r.samples) {
        ++data.dropped_epochs;
        ++in_selection;
        continue;
      }
      Epoch epoch;
      epoch.event = e;
      epoch.channels = signal.channels;
      epoch.samples = length;
      epoch.data = span(signal, first, length);
      if (reject_uv > 0.0 && peakToPeak(epoch, extractor.channelIndices()) > reject_uv) {
        ++data.rejected_epochs;
        ++in_selection;
        continue;
      }
      rows.push_back(extractor.features(epoch));
      const std::int64_t erp_first = e.sample - erp_baseline;
      if (e.known && erp_first >= 0 && erp_first + erp_length <= r.samples)
        erps.add(span(erp_source, erp_first, erp_length), e.target);
      data.target.push_back(e.target);
      data.code.push_back(e.code);
      data.sequence.push_back(in_selection / layout.codes());
      data.selection.push_back(static_cast<int>(data.selections.size()) - 1);
      data.file.push_back(static_cast<int>(f));
      data.sample.push_back(e.sample);
      data.selections.back().epochs.push_back(static_cast<int>(rows.size()) - 1);
      if (e.target) data.selections.back().target_codes.insert(e.code);
      ++in_selection;
    }
  }
  if (rows.empty() && data.rejected_epochs > 0) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", reject_uv);
    throw std::invalid_argument("every epoch (" + std::to_string(data.rejected_epochs) +
                                ") is over the rejection limit of " + limit +
                                " uV peak-to-peak: nothing is left; raise --reject-uv (or 0: off)");
  }
  data.features.resize(static_cast<Eigen::Index>(rows.size()), data.shape.size());
  for (size_t i = 0; i < rows.size(); ++i)
    data.features.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  std::map<int, std::pair<int, int>> by_code;  // code: targets, flashes
  for (size_t i = 0; i < data.code.size(); ++i) {
    auto& [targets, flashes] = by_code[data.code[i]];
    targets += data.target[i];
    ++flashes;
  }
  data.codes_are_classes =
      data.layout.kind == ParadigmLayout::Kind::SingleStimulus && !by_code.empty() &&
      std::all_of(
          by_code.begin(), by_code.end(),
          [](const auto& c) { return c.second.first == 0 || c.second.first == c.second.second; }) &&
      std::any_of(by_code.begin(), by_code.end(), [](const auto& c) { return c.second.first > 0; });
  data.reject_uv = reject_uv;
  data.erp = erps.curves();
  data.erp.channels = data.info.channels;
  data.erp.rate_hz = data.info.rate_hz;
  data.erp.start_s = -erp_baseline / data.info.rate_hz;
  data.erp.baseline_s = erp_baseline / data.info.rate_hz;
  data.erp.window_start_s = settings.window.start_s;
  // The features average whole bins: the samples past the last whole bin are not used.
  data.erp.window_end_s =
      settings.window.start_s + data.shape.bins * extractor.factor() / data.info.rate_hz;
  data.erp.highpass_hz = settings.filter.highpass_hz;
  data.erp.lowpass_hz = settings.filter.lowpass_hz;
  data.erp.notch_hz = settings.filter.notch_hz;
  data.erp.filter_order = settings.filter.order;
  data.erp.notch_q = settings.filter.notch_q;
  data.erp.common_average = settings.filter.common_average;
  data.erp.selections = static_cast<int>(data.selections.size());
  data.erp.zero_phase = settings.zero_phase || erp_own_pass;
  if (progress) progress(1.0, "epochs ready");
  return data;
}

}  // namespace arbci::bci
