#include "arbci/bci/signal_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace arbci::bci {
namespace {

// The amplitude of the sinusoid at `hz` in the detrended signal (Hann window, Goertzel).
double amplitudeAt(const std::vector<double>& y, double hz, double rate_hz) {
  const int n = static_cast<int>(y.size());
  if (n < 2 || hz >= rate_hz / 2.0) return 0.0;
  const double w = 2.0 * std::numbers::pi * hz / rate_hz;
  double re = 0.0, im = 0.0, window_sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double hann = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * k / (n - 1));
    re += hann * y[static_cast<size_t>(k)] * std::cos(w * k);
    im -= hann * y[static_cast<size_t>(k)] * std::sin(w * k);
    window_sum += hann;
  }
  return 2.0 * std::hypot(re, im) / window_sum;
}

// Line noise is a peak: the amplitude at the line frequency at least this many times the mean of
// its neighbours 2 to 6 Hz either side. Broadband noise (a loose electrode, muscle) is as strong
// at 50 or 60 Hz as beside them and is graded by its RMS instead (one frequency of white noise
// stands four times above the mean of ten others about once in a hundred thousand).
constexpr double kLinePeakRatio = 4.0;

bool isPeak(const std::vector<double>& y, double hz, double rate_hz) {
  double beside = 0.0;
  for (const double d : {2.0, 3.0, 4.0, 5.0, 6.0}) {
    beside += (amplitudeAt(y, hz - d, rate_hz) + amplitudeAt(y, hz + d, rate_hz)) / 10.0;
  }
  return amplitudeAt(y, hz, rate_hz) >= kLinePeakRatio * beside;
}

struct Finding {
  Grade grade;
  std::string text;
};

Finding graded(const char* what, double value, double poor, double bad, const char* unit = "uV") {
  char text[96];
  if (value > bad) {
    std::snprintf(text, sizeof text, "%s %.1f %s (bad above %g)", what, value, unit, bad);
    return {Grade::Bad, text};
  }
  if (value > poor) {
    std::snprintf(text, sizeof text, "%s %.1f %s (poor above %g)", what, value, unit, poor);
    return {Grade::Poor, text};
  }
  return {Grade::Good, ""};
}

}  // namespace

const char* toString(Grade grade) {
  switch (grade) {
    case Grade::Good:
      return "good";
    case Grade::Poor:
      return "poor";
    case Grade::Bad:
      return "bad";
  }
  return "good";
}

SignalQuality assessSignal(const float* x, int n, double rate_hz, const QualityThresholds& t) {
  SignalQuality q;
  if (n < 2 || rate_hz <= 0.0) {
    q.finding = "no signal yet";
    return q;
  }
  // Linear trend by least squares over time in seconds: its slope is the drift.
  double mean_t = 0.0, mean_x = 0.0, peak = 0.0;
  for (int k = 0; k < n; ++k) {
    mean_t += k / rate_hz;
    mean_x += x[k];
    peak = std::max(peak, std::abs(static_cast<double>(x[k])));
  }
  mean_t /= n;
  mean_x /= n;
  double stt = 0.0, stx = 0.0, sxx = 0.0;
  for (int k = 0; k < n; ++k) {
    const double dt = k / rate_hz - mean_t, dx = x[k] - mean_x;
    stt += dt * dt;
    stx += dt * dx;
    sxx += dx * dx;
  }
  const double slope = stt > 0.0 ? stx / stt : 0.0;
  q.drift_uv_s = slope;
  q.sd_uv = std::sqrt(sxx / n);
  std::vector<double> detrended(static_cast<size_t>(n));
  double sum_sq = 0.0;
  for (int k = 0; k < n; ++k) {
    const double y = x[k] - mean_x - slope * (k / rate_hz - mean_t);
    detrended[static_cast<size_t>(k)] = y;
    sum_sq += y * y;
  }
  q.rms_uv = std::sqrt(sum_sq / n);
  q.line50_uv = amplitudeAt(detrended, 50.0, rate_hz);
  q.line60_uv = amplitudeAt(detrended, 60.0, rate_hz);
  const bool peak50 = isPeak(detrended, 50.0, rate_hz), peak60 = isPeak(detrended, 60.0, rate_hz);
  q.flat = q.sd_uv < t.flat_sd_uv;
  q.saturated = peak >= t.saturated_uv;

  char text[96];
  if (q.saturated) {
    std::snprintf(text, sizeof text, "saturated: %.0f uV (bad at %g)", peak, t.saturated_uv);
    q.grade = Grade::Bad;
    q.finding = text;
    return q;
  }
  if (q.flat) {
    std::snprintf(text, sizeof text, "flat: SD %.2f uV (bad below %g)", q.sd_uv, t.flat_sd_uv);
    q.grade = Grade::Bad;
    q.finding = text;
    return q;
  }
  // The stronger of the two lines that stand out from their neighbours; none when neither does.
  const bool grade50 = t.line_hz == 0.0 || std::abs(t.line_hz - 50.0) < 1.0;
  const bool grade60 = t.line_hz == 0.0 || std::abs(t.line_hz - 60.0) < 1.0;
  const double line50 = peak50 && grade50 ? q.line50_uv : 0.0;
  const double line60 = peak60 && grade60 ? q.line60_uv : 0.0;
  const bool fifty = line50 >= line60;
  const Finding findings[] = {
      graded(fifty ? "line noise 50 Hz" : "line noise 60 Hz", fifty ? line50 : line60,
             t.line_poor_uv, t.line_bad_uv),
      graded("drift", std::abs(q.drift_uv_s), t.drift_poor_uv_s, t.drift_bad_uv_s, "uV/s"),
      graded("RMS", q.rms_uv, t.rms_poor_uv, t.rms_bad_uv),
  };
  for (const Finding& f : findings) {
    if (static_cast<int>(f.grade) > static_cast<int>(q.grade)) {
      q.grade = f.grade;
      q.finding = f.text;
    }
  }
  if (q.grade == Grade::Good) {
    std::snprintf(text, sizeof text, "RMS %.1f uV", q.rms_uv);
    q.finding = text;
  }
  return q;
}

}  // namespace arbci::bci
