#include "arbci/bci/filters.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>

namespace arbci::bci {
namespace {

void checkDesign(int order, double cutoff_hz, double rate_hz, const char* what) {
  if (order < 1 || order > 12)
    throw std::invalid_argument(std::string(what) + ": order must be 1-12");
  if (!(cutoff_hz > 0.0 && cutoff_hz < rate_hz / 2.0)) {
    throw std::invalid_argument(std::string(what) + ": cut-off " + std::to_string(cutoff_hz) +
                                " Hz must lie between 0 and half the sampling rate (" +
                                std::to_string(rate_hz / 2.0) + " Hz)");
  }
}

// Butterworth sections of a low-pass (highpass = false) or high-pass prototype.
std::vector<Biquad> butterworth(int order, double cutoff_hz, double rate_hz, bool highpass) {
  const double k = std::tan(std::numbers::pi * cutoff_hz / rate_hz);
  std::vector<Biquad> sections;
  for (int i = 0; i < order / 2; ++i) {
    const double q = 1.0 / (2.0 * std::sin(std::numbers::pi * (2 * i + 1) / (2.0 * order)));
    const double norm = 1.0 / (1.0 + k / q + k * k);
    Biquad s;
    if (highpass) {
      s.b0 = norm;
      s.b1 = -2.0 * norm;
    } else {
      s.b0 = k * k * norm;
      s.b1 = 2.0 * s.b0;
    }
    s.b2 = s.b0;
    s.a1 = 2.0 * (k * k - 1.0) * norm;
    s.a2 = (1.0 - k / q + k * k) * norm;
    sections.push_back(s);
  }
  if (order % 2 == 1) {
    Biquad s;
    s.a1 = (k - 1.0) / (k + 1.0);
    s.b0 = highpass ? 1.0 / (1.0 + k) : k / (1.0 + k);
    s.b1 = highpass ? -s.b0 : s.b0;
    sections.push_back(s);
  }
  return sections;
}

}  // namespace

std::vector<Biquad> butterworthLowpass(int order, double cutoff_hz, double rate_hz) {
  checkDesign(order, cutoff_hz, rate_hz, "low-pass");
  return butterworth(order, cutoff_hz, rate_hz, false);
}

std::vector<Biquad> butterworthHighpass(int order, double cutoff_hz, double rate_hz) {
  checkDesign(order, cutoff_hz, rate_hz, "high-pass");
  return butterworth(order, cutoff_hz, rate_hz, true);
}

Biquad notchFilter(double frequency_hz, double q, double rate_hz) {
  checkDesign(2, frequency_hz, rate_hz, "notch");
  if (!(q > 0.0)) throw std::invalid_argument("notch: quality must be positive");
  const double w0 = 2.0 * std::numbers::pi * frequency_hz / rate_hz;
  const double alpha = std::sin(w0) / (2.0 * q);
  const double a0 = 1.0 + alpha;
  Biquad s;
  s.b0 = 1.0 / a0;
  s.b1 = -2.0 * std::cos(w0) / a0;
  s.b2 = 1.0 / a0;
  s.a1 = s.b1;
  s.a2 = (1.0 - alpha) / a0;
  return s;
}

double magnitudeResponse(const std::vector<Biquad>& sections, double frequency_hz, double rate_hz) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * std::numbers::pi * frequency_hz / rate_hz);
  const std::complex<double> z2 = z1 * z1;
  std::complex<double> h = 1.0;
  for (const Biquad& s : sections)
    h *= (s.b0 + s.b1 * z1 + s.b2 * z2) / (1.0 + s.a1 * z1 + s.a2 * z2);
  return std::abs(h);
}

IirFilter::IirFilter(std::vector<Biquad> sections, int channels)
    : sections_(std::move(sections)),
      channels_(channels),
      state_(static_cast<size_t>(channels) * sections_.size() * 2, 0.0) {}

void IirFilter::reset() {
  std::fill(state_.begin(), state_.end(), 0.0);
  started_ = false;
}

// A constant input x gives each section the output g x (g its gain at DC) for ever; the two
// state words that hold it follow from the section's equations with x and y fixed.
void IirFilter::settleOn(int channel, double value) {
  const size_t n_sections = sections_.size();
  double* z = state_.data() + static_cast<size_t>(channel) * n_sections * 2;
  double x = value;
  for (size_t k = 0; k < n_sections; ++k) {
    const Biquad& q = sections_[k];
    const double denominator = 1.0 + q.a1 + q.a2;
    const double y = std::abs(denominator) > 1e-300 ? (q.b0 + q.b1 + q.b2) * x / denominator : 0.0;
    z[2 * k + 1] = q.b2 * x - q.a2 * y;
    z[2 * k] = y - q.b0 * x;
    x = y;
  }
}

void IirFilter::process(Block& block) {
  if (block.channels != channels_) {
    throw std::invalid_argument("filter: block has " + std::to_string(block.channels) +
                                " channels, the filter " + std::to_string(channels_));
  }
  const size_t n_sections = sections_.size();
  if (!started_ && block.samples > 0) {
    for (int c = 0; c < channels_; ++c)
      settleOn(c, block.data[static_cast<size_t>(c) * block.samples]);
    started_ = true;
  }
  for (int c = 0; c < channels_; ++c) {
    float* x = block.data.data() + static_cast<size_t>(c) * block.samples;
    double* z = state_.data() + static_cast<size_t>(c) * n_sections * 2;
    for (int s = 0; s < block.samples; ++s) {
      double v = x[s];
      for (size_t k = 0; k < n_sections; ++k) {
        const Biquad& q = sections_[k];
        const double y = q.b0 * v + z[2 * k];
        z[2 * k] = q.b1 * v - q.a1 * y + z[2 * k + 1];
        z[2 * k + 1] = q.b2 * v - q.a2 * y;
        v = y;
      }
      x[s] = static_cast<float>(v);
    }
  }
}

void commonAverageReference(Block& block) {
  if (block.channels < 2) return;
  for (int s = 0; s < block.samples; ++s) {
    double mean = 0.0;
    for (int c = 0; c < block.channels; ++c) mean += block.at(c, s);
    mean /= block.channels;
    for (int c = 0; c < block.channels; ++c)
      block.at(c, s) = static_cast<float>(block.at(c, s) - mean);
  }
}

namespace {

std::vector<Biquad> chainSections(const FilterSettings& f, double rate) {
  std::vector<Biquad> sections;
  if (f.highpass_hz > 0.0) {
    const auto hp = butterworthHighpass(f.order, f.highpass_hz, rate);
    sections.insert(sections.end(), hp.begin(), hp.end());
  }
  if (f.lowpass_hz > 0.0) {
    const auto lp = butterworthLowpass(f.order, f.lowpass_hz, rate);
    sections.insert(sections.end(), lp.begin(), lp.end());
  }
  if (f.highpass_hz > 0.0 && f.lowpass_hz > 0.0 && f.highpass_hz >= f.lowpass_hz) {
    throw std::invalid_argument("band-pass: high-pass " + std::to_string(f.highpass_hz) +
                                " Hz must be below low-pass " + std::to_string(f.lowpass_hz) +
                                " Hz");
  }
  if (f.notch_hz > 0.0) sections.push_back(notchFilter(f.notch_hz, f.notch_q, rate));
  return sections;
}

}  // namespace

FilterChain::FilterChain(const FilterSettings& settings, const SignalInfo& info)
    : settings_(settings),
      rate_hz_(info.rate_hz),
      filter_(chainSections(settings, info.rate_hz), info.channelCount()) {}

void FilterChain::process(Block& block) {
  if (settings_.common_average) commonAverageReference(block);
  filter_.process(block);
}

double FilterChain::magnitude(double frequency_hz) const {
  return magnitudeResponse(filter_.sections(), frequency_hz, rate_hz_);
}

Decimator::Decimator(int factor, int channels)
    : factor_(factor), channels_(channels), sums_(static_cast<size_t>(channels), 0.0) {
  if (factor < 1) throw std::invalid_argument("decimation factor must be at least 1");
}

Block Decimator::process(const Block& block) {
  if (block.channels != channels_)
    throw std::invalid_argument("decimator: block has another channel count");
  if (next_input_ >= 0 && block.first_sample != next_input_) {
    throw std::invalid_argument("decimator: block starts at sample " +
                                std::to_string(block.first_sample) + ", expected " +
                                std::to_string(next_input_));
  }
  // Groups start at multiples of the factor; samples before the first whole group are skipped.
  std::int64_t index = block.first_sample;
  int s = 0;
  if (next_input_ < 0) {
    const std::int64_t aligned = (index + factor_ - 1) / factor_ * factor_;
    s = static_cast<int>(std::min<std::int64_t>(aligned - index, block.samples));
    index += s;
  }
  const std::int64_t first_group = (index - count_) / factor_;
  const int produced = static_cast<int>((count_ + (block.samples - s)) / factor_);
  Block out(first_group, channels_, produced);
  int written = 0;
  for (; s < block.samples; ++s, ++index) {
    for (int c = 0; c < channels_; ++c) sums_[static_cast<size_t>(c)] += block.at(c, s);
    if (++count_ == factor_) {
      for (int c = 0; c < channels_; ++c) {
        out.at(c, written) = static_cast<float>(sums_[static_cast<size_t>(c)] / factor_);
        sums_[static_cast<size_t>(c)] = 0.0;
      }
      ++written;
      count_ = 0;
    }
  }
  next_input_ = block.endSample();
  return out;
}

void filterWhole(Block& signal, const FilterSettings& settings, const SignalInfo& info,
                 bool zero_phase) {
  FilterChain(settings, info).process(signal);
  if (!zero_phase) return;
  const auto reverseInTime = [&signal] {
    for (int c = 0; c < signal.channels; ++c) {
      auto first = signal.data.begin() + static_cast<std::ptrdiff_t>(c) * signal.samples;
      std::reverse(first, first + signal.samples);
    }
  };
  reverseInTime();
  FilterChain(settings, info).process(signal);
  reverseInTime();
}

}  // namespace arbci::bci
