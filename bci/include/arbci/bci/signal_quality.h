// Per-channel signal quality for the experimenter's EEG view: over the last seconds of raw
// signal, whether a channel is flat or saturated, how much line noise (50 and 60 Hz) it carries,
// how fast it drifts, and its RMS; each graded good / poor / bad against a threshold the finding
// names, so the experimenter knows what "red" means without a manual.
#pragma once

#include <string>

#include "arbci/bci/channel_quality.h"

namespace arbci::bci {

enum class Grade { Good, Poor, Bad };
const char* toString(Grade grade);  // "good", "poor", "bad"

// Where a line, a drift and an RMS turn bad: the EEG panel's grading and the session's quality gate
// (gates.*, whose defaults these are).
inline constexpr double kLineBadUv = 20.0, kDriftBadUvS = 200.0, kRmsBadUv = 100.0;

// Where a finding turns poor (amber) and bad (red). Scalp EEG is tens of microvolts: a channel
// far above that carries an artefact or a loose electrode.
struct QualityThresholds {
  double flat_sd_uv = kFlatSdUv;  // standard deviation below this: flat (bad)
  double saturated_uv = 5000.0;   // a sample this far from zero: the amplifier's range (bad)
  double line_poor_uv = 5.0;      // amplitude at 50 or 60 Hz
  double line_bad_uv = kLineBadUv;
  double drift_poor_uv_s = 50.0;  // the window's linear trend
  double drift_bad_uv_s = kDriftBadUvS;
  double rms_poor_uv = 50.0;  // about the trend
  double rms_bad_uv = kRmsBadUv;
  // The lab's power line (the notch's frequency): only its line is graded; 0: 50 and 60 Hz both.
  double line_hz = 0.0;
};

struct SignalQuality {
  double rms_uv = 0.0, sd_uv = 0.0, line50_uv = 0.0, line60_uv = 0.0, drift_uv_s = 0.0;
  bool flat = false, saturated = false;
  Grade grade = Grade::Good;
  // The worst finding and its threshold ("line noise 50 Hz: 23.1 uV (bad above 20)"), or
  // "RMS 12.3 uV" when good.
  std::string finding;
};

// `x`: `n` raw samples of one channel at `rate_hz` (two seconds make the 50/60 Hz amplitudes
// exact to 0.5 Hz).
SignalQuality assessSignal(const float* x, int n, double rate_hz,
                           const QualityThresholds& thresholds = {});

}  // namespace arbci::bci
