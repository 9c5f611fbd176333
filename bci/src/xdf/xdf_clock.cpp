#include "xdf_clock.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arbci::bci::xdf {
namespace {

// A break in a regular stream: its stamps, less one period per sample, shift by at least this and
// stay shifted (a gap in the samples, or a clock that stepped). Stamps jitter by milliseconds
// per sample, and by tens of milliseconds where chunks are stamped as they arrive; a step alone
// proves nothing, so a step of this size is only a candidate, kept when the median level of the
// stamps over the half second after it differs from the half second before it by this much too.
constexpr double kBreakS = 0.05;
constexpr double kLevelWindowS = 0.5;
constexpr std::size_t kLevelSamples = 3;
// A clock reset: successive offsets whose collection times step back, or forward by more than
// kResetTimeS and kResetStds spreads beyond the usual interval, while their values jump by more
// than kResetValueS and kResetStds spreads (pyxdf's criteria, with its thresholds).
constexpr double kResetTimeS = 5.0, kResetValueS = 1.0;
constexpr double kResetTimeStds = 5.0, kResetValueStds = 10.0;
// An outlier: a stamp further than both of these from its stretch's robust line. Jitter of LSL's
// chunk stamps is milliseconds to tens of them; the floor keeps every stamp a late chunk explains
// in the fit (a stamp kept 0.1 s off moves a line through n stamps by 0.1/n s at most).
constexpr double kOutlierS = 0.1;
constexpr double kOutlierSpreads = 10.0;
// A stamp this far outside its segment's offsets (before the first, after the last) may belong
// to the next segment, if it lies within that one.
constexpr double kSegmentMarginS = 10.0;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), middle, v.end());
  return *middle;
}

struct Line {
  double a = 0.0, b = 0.0;  // y = a + b * x
};

// Least squares, centred (collection times are large numbers and the slope tiny).
Line fit(const std::vector<double>& x, const std::vector<double>& y, std::size_t first,
         std::size_t last) {
  const double n = static_cast<double>(last - first + 1);
  double mx = 0.0, my = 0.0;
  for (std::size_t i = first; i <= last; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = first; i <= last; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  Line line;
  line.b = sxx > 0.0 ? sxy / sxx : 0.0;
  line.a = my - line.b * mx;
  return line;
}

struct Segment {
  double start = 0.0, end = 0.0;  // collection times of its first and last offset
  Line offset;                    // offset = a + b * stamp
  bool contains(double t) const {
    return t >= start - kSegmentMarginS && t <= end + kSegmentMarginS;
  }
};

std::vector<Segment> clockSegments(const Stream& s, int& resets) {
  std::vector<double> times, values;
  for (const auto& [time, value] : s.offsets) {
    times.push_back(time);
    values.push_back(value);
  }
  const std::size_t n = times.size();
  std::vector<std::size_t> starts{0};
  if (n >= 3) {
    std::vector<double> dt(n - 1), dv(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i) {
      dt[i] = times[i + 1] - times[i];
      dv[i] = std::abs(values[i + 1] - values[i]);
    }
    const double eps = std::numeric_limits<double>::epsilon();
    const double mt = median(dt), mv = median(dv);
    std::vector<double> st(n - 1), sv(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i) {
      st[i] = std::abs(dt[i] - mt);
      sv[i] = std::abs(dv[i] - mv);
    }
    const double spread_t = median(st) + eps, spread_v = median(sv) + eps;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const bool time_glitch =
          dt[i] < 0 || ((dt[i] - mt) / spread_t > kResetTimeStds && dt[i] - mt > kResetTimeS);
      const bool value_glitch =
          (dv[i] - mv) / spread_v > kResetValueStds && dv[i] - mv > kResetValueS;
      if (time_glitch && value_glitch) starts.push_back(i + 1);
    }
  }
  resets += static_cast<int>(starts.size()) - 1;
  std::vector<Segment> out;
  if (n == 0) return out;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t first = starts[k];
    const std::size_t last = k + 1 < starts.size() ? starts[k + 1] - 1 : n - 1;
    Segment segment;
    segment.start = times[first];
    segment.end = times[last];
    segment.offset = fit(times, values, first, last);
    out.push_back(segment);
  }
  return out;
}

// Where a regular stream's stamps break (see kBreakS): `level` is each stamp less its index's
// share of the nominal period, flat with jitter between breaks.
std::vector<ClockReport::Break> breaksIn(const std::vector<double>& stamps, double period) {
  std::vector<ClockReport::Break> out;
  const std::size_t n = stamps.size();
  const auto window = static_cast<std::size_t>(std::max(8.0, kLevelWindowS / period));
  auto level = [&](std::size_t from, std::size_t to) {  // median over [from, to)
    std::vector<double> v;
    v.reserve(to - from);
    for (std::size_t i = from; i < to; ++i)
      v.push_back(stamps[i] - static_cast<double>(i) * period);
    return median(std::move(v));
  };
  std::size_t stretch = 0;  // where the stretch the candidate ends began
  for (std::size_t i = 1; i < n; ++i) {
    const double step = stamps[i] - stamps[i - 1];
    if (step - period <= kBreakS && step >= -kBreakS) continue;
    // Levels of at least kLevelSamples stamps each side: one wild stamp at either end of the
    // stream is never a level of its own (it is an outlier of the line).
    const std::size_t before = std::max(stretch, i - std::min(i, window)),
                      after = std::min(n, i + window);
    if (i - before < kLevelSamples || after - i < kLevelSamples) continue;
    const double shift = level(i, after) - level(before, i);
    if (std::abs(shift) < kBreakS) continue;  // a late or early stamp, not a break
    out.push_back({i, shift});
    stretch = i;
  }
  return out;
}

// stamps[first, end) as a + b * index, fitted so that no single stamp can move it: a line through
// medians first (the slope from stamps half the stretch apart, which outliers among them cannot
// pull; the intercept the median of what is left), then least squares over the stamps within the
// outlier limit of it. Counts what it left out into `report`.
Line robustFit(const std::vector<double>& stamps, std::size_t first, std::size_t end,
               ClockReport& report) {
  const std::size_t n = end - first;
  const std::size_t lag = std::max<std::size_t>(1, n / 2);
  std::vector<double> slopes;
  for (std::size_t i = first; i + lag < end; ++i)
    slopes.push_back((stamps[i + lag] - stamps[i]) / static_cast<double>(lag));
  const double b = median(std::move(slopes));
  std::vector<double> residual(n);
  for (std::size_t i = 0; i < n; ++i)
    residual[i] = stamps[first + i] - b * static_cast<double>(first + i);
  const double a = median(residual);
  std::vector<double> distance(n);
  for (std::size_t i = 0; i < n; ++i) distance[i] = std::abs(residual[i] - a);
  const double spread = 1.4826 * median(distance);  // a robust standard deviation
  const double limit = std::max(kOutlierS, kOutlierSpreads * spread);
  double sx = 0.0, sy = 0.0, count = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] > limit) {
      ++report.outliers;
      report.largest_outlier_s = std::max(report.largest_outlier_s, distance[i]);
      continue;
    }
    sx += static_cast<double>(first + i);
    sy += stamps[first + i];
    ++count;
  }
  // Centred least squares over the stamps kept (at least half of them, by the median).
  const double mx = sx / count, my = sy / count;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] > limit) continue;
    const double x = static_cast<double>(first + i) - mx;
    sxy += x * (stamps[first + i] - my);
    sxx += x * x;
  }
  Line line;
  line.b = sxx > 0.0 ? sxy / sxx : b;
  line.a = my - line.b * mx;
  return line;
}

}  // namespace

std::vector<double> recorderStamps(const Stream& s, ClockReport& report) {
  std::vector<double> stamps = s.stamps;
  const std::vector<Segment> segments = clockSegments(s, report.resets);
  // Each stamp, in the order recorded, in the segment of its clock: the next one once the
  // stream's own stamps step back (its clock was reset), or once a stamp lies in a later one.
  std::size_t current = 0;
  for (std::size_t i = 0; i < stamps.size() && !segments.empty(); ++i) {
    const double t = s.stamps[i];
    if (i > 0 && t < s.stamps[i - 1] - 1.0 && current + 1 < segments.size()) {
      ++current;
    } else if (!segments[current].contains(t)) {
      for (std::size_t j = current + 1; j < segments.size(); ++j) {
        if (segments[j].contains(t)) {
          current = j;
          break;
        }
      }
    }
    const Line& line = segments[current].offset;
    stamps[i] = t + line.a + line.b * t;
  }
  if (s.nominal_rate <= 0.0 || stamps.size() < 2) return stamps;
  report.breaks = breaksIn(stamps, 1.0 / s.nominal_rate);
  // Dejitter each stretch between breaks: stamps = a + b * index.
  std::size_t first = 0;
  for (std::size_t k = 0; k <= report.breaks.size(); ++k) {
    const std::size_t end = k < report.breaks.size() ? report.breaks[k].sample : stamps.size();
    if (end - first >= 2) {
      const Line line = robustFit(stamps, first, end, report);
      for (std::size_t i = first; i < end; ++i)
        stamps[i] = line.a + line.b * static_cast<double>(i);
    }
    first = end;
  }
  return stamps;
}

}  // namespace arbci::bci::xdf
