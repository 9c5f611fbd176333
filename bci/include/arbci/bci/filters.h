// Causal filtering of blocks: common average reference, IIR band-pass and notch (biquad
// cascades whose state carries across blocks, so filtering block by block gives exactly the
// output of filtering the whole signal) and decimation by moving average. A cascade starts in
// the steady state of its first sample held since ever (each channel its own): a DC-coupled
// amplifier's offset of millivolts is not a step that rings through the high-pass for seconds.
#pragma once

#include <vector>

#include "arbci/bci/signal.h"

namespace arbci::bci {

struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;  // a0 = 1
};

// Butterworth sections by the bilinear transform (cut-offs pre-warped). Throw
// std::invalid_argument unless 0 < cutoff < rate / 2 and 1 <= order <= 12.
std::vector<Biquad> butterworthLowpass(int order, double cutoff_hz, double rate_hz);
std::vector<Biquad> butterworthHighpass(int order, double cutoff_hz, double rate_hz);
// A second-order notch of quality `q` (bandwidth = frequency / q).
Biquad notchFilter(double frequency_hz, double q, double rate_hz);
// Magnitude response of a cascade at `frequency_hz`.
double magnitudeResponse(const std::vector<Biquad>& sections, double frequency_hz, double rate_hz);

// A biquad cascade with one state per channel (transposed direct form II, in double). Its state
// starts as if each channel's first sample had always been its value (the steady state of a
// constant input), so an offset passes without a start-up transient.
class IirFilter {
 public:
  IirFilter(std::vector<Biquad> sections, int channels);
  void process(Block& block);  // in place
  // Forgets the signal: the next sample starts it again (in its steady state).
  void reset();
  const std::vector<Biquad>& sections() const { return sections_; }

 private:
  void settleOn(int channel, double value);  // the steady state of `value` held

  std::vector<Biquad> sections_;
  int channels_;
  std::vector<double> state_;  // [channel][section][2]
  bool started_ = false;
};

// Subtracts the mean over channels from every sample.
void commonAverageReference(Block& block);

// Each field's default, range and meaning: bci::filterSchema() (bci/settings.h).
struct FilterSettings {
  FilterSettings();  // the schema's defaults
  bool operator==(const FilterSettings&) const = default;
  bool common_average;
  double highpass_hz;  // 0: none
  double lowpass_hz;   // 0: none
  int order;           // of each Butterworth half
  double notch_hz;     // 0: none (60 in the Americas)
  double notch_q;
};

// The cleaning stage of the cycle: CAR, band-pass and notch, in that order.
class FilterChain {
 public:
  // Throws std::invalid_argument naming the setting that does not fit `info`'s rate.
  FilterChain(const FilterSettings& settings, const SignalInfo& info);
  void process(Block& block);
  double magnitude(double frequency_hz) const;  // of the IIR part

 private:
  FilterSettings settings_;
  double rate_hz_;
  IirFilter filter_;
};

// A whole recorded signal through a fresh chain (block by block or whole, the same); with
// `zero_phase`, backward again through another fresh chain, so that the phase lags cancel
// (offline only: the online cycle must stay causal).
void filterWhole(Block& signal, const FilterSettings& settings, const SignalInfo& info,
                 bool zero_phase);

// Keeps every `factor`-th sample of the moving average over the last `factor` samples; output
// sample k covers input samples [k*factor, (k+1)*factor). State carries across blocks.
class Decimator {
 public:
  Decimator(int factor, int channels);
  Block process(const Block& block);  // the block of output samples completed by `block`
  int factor() const { return factor_; }

 private:
  int factor_, channels_;
  std::vector<double> sums_;
  int count_ = 0;
  std::int64_t next_input_ = -1;
};

}  // namespace arbci::bci
