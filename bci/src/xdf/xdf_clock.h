// An XDF stream's timestamps on the recorder's clock, as pyxdf puts them: the stream's clock
// offsets (measured by the recorder every few seconds) fitted by a line per clock segment and
// added to its stamps, a segment ending where the stream's clock was reset (its offsets jump in
// both collection time and value); then, for a regular stream, the stamps of each stretch without
// a break replaced by a straight line through them (dejittered: LSL stamps chunks as they arrive,
// not samples as they are taken). A break (the stamps shift by 50 ms or more and stay shifted: a
// gap in the samples, or a clock that stepped) is kept and reported, never closed up. A stamp
// that is late or early is jitter, and the line goes through it; one that no line through its
// neighbours explains (further from the stretch's robust line than 0.1 s and ten spreads of its
// stamps: a flipped bit, a clock read wrong) is an outlier, left out of the line and counted, and
// its sample keeps the place the line gives it.
#pragma once

#include <cstddef>
#include <vector>

#include "xdf_file.h"

namespace arbci::bci::xdf {

struct ClockReport {
  int resets = 0;  // clock resets found in the offsets
  // Regular streams: where a break falls (the index of the first sample after it) and how long
  // it is, in seconds beyond one sample period.
  struct Break {
    std::size_t sample = 0;
    double seconds = 0.0;
  };
  std::vector<Break> breaks;
  // Regular streams: stamps left out of their stretch's line as outliers, and the largest's
  // distance from it.
  std::size_t outliers = 0;
  double largest_outlier_s = 0.0;
};

// The stream's stamps on the recorder's clock (dejittered when `regular`).
std::vector<double> recorderStamps(const Stream& stream, ClockReport& report);

}  // namespace arbci::bci::xdf
