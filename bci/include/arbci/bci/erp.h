// Event-related potentials as a reviewer expects them: per channel the average response to
// targets and to non-targets on the filtered signal, each epoch baseline-corrected (the mean of
// its pre-stimulus interval subtracted), with the standard error of each average across epochs.
// The numbers behind the ERP figures (erp.png, erp.json, the Training panel).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace arbci::bci {

struct ErpCurves {
  std::vector<std::string> channels;
  double rate_hz = 0.0;
  double start_s = 0.0;     // the first sample's time after the stimulus (negative: the baseline)
  double baseline_s = 0.0;  // [start_s, start_s + baseline_s) is each epoch's baseline
  double window_start_s = 0.0, window_end_s = 0.0;  // the samples the features use
  // The filter the averaged signal went through, stated on every figure: a figure's filter
  // changes the ERP's shape (a causal band-pass delays and rings), so it is part of the result.
  double highpass_hz = 0.0, lowpass_hz = 0.0, notch_hz = 0.0;  // 0: none
  int filter_order = 0;     // of each Butterworth half (high-pass, low-pass)
  double notch_q = 0.0;     // the notch's quality factor
  bool zero_phase = false;  // forward and backward (no lag) rather than causal (as online)
  bool filtered() const { return highpass_hz > 0.0 || lowpass_hz > 0.0 || notch_hz > 0.0; }
  // "4th-order Butterworth 0.5-20 Hz band-pass, 50 Hz notch (Q 30), zero-phase", or "unfiltered".
  std::string filterText() const;
  // The reference the averages are on: the common average (subtracted first) or the amplifier's.
  bool common_average = false;
  std::string referenceText() const;  // "common average" or "as recorded"
  // Channels left out of the recordings before averaging, each with its reason ("flat").
  std::vector<std::pair<std::string, std::string>> excluded;
  int selections = 0;           // the selections the epochs come from (0: no selections)
  int targets = 0, others = 0;  // epochs averaged
  // Channels (rows) x samples (columns), microvolts.
  Eigen::MatrixXd target_mean, other_mean, target_se, other_se;
  // Signed r^2 (the point-biserial correlation of amplitude with target/non-target, squared,
  // with the sign of the difference): how much of each sample's variance the class explains.
  Eigen::MatrixXd signed_r2;

  int samples() const { return static_cast<int>(target_mean.cols()); }
  double timeS(int sample) const { return start_s + sample / rate_hz; }
  Eigen::MatrixXd difference() const { return target_mean - other_mean; }
  // The sample where the difference's root mean square over channels peaks.
  int peakSample() const;
  // One scale for every channel's figure: the largest |average| + 1.96 SE or |difference|,
  // rounded up (at least 1 uV).
  double scaleUv() const;
  // One channel's row as a vector (a row of a column-major matrix is strided).
  static std::vector<double> row(const Eigen::MatrixXd& m, int channel);
};

// The difference at its peak on the scalp: the channels whose 10-20 positions are known, and the
// value anywhere on the head by inverse-distance weighting (power 2) between them.
struct ScalpMap {
  struct Electrode {
    std::string name;
    double x, y;  // bci::electrodePosition's plane
    double uv;
  };
  double time_s = 0.0;
  std::vector<Electrode> electrodes;
  double limit_uv = 0.0;  // the largest |value| (>= 1e-6)
  double at(double x, double y) const;
};
// Where the scalp map is drawn: the difference's peak (root mean square over channels) inside a
// search window (the P300's, by default), or a time given.
struct ScalpTime {
  double from_s = 0.25, to_s = 0.6;  // the search window, after the stimulus
  std::optional<double> at_s;        // a time given: the sample nearest it
};
// The sample the scalp map is drawn at: the largest local peak of the difference (root mean
// square over channels) inside the window, clipped to the epoch (the whole epoch when the window
// holds none of it); the window's largest value where it holds no peak. Never an edge merely
// because drift grows there or an earlier peak is still falling.
int scalpSample(const ErpCurves& erp, const ScalpTime& when);
// None when fewer than 3 channels have known positions.
std::optional<ScalpMap> scalpMapAt(const ErpCurves& erp, const ScalpTime& when = {});

// Sums epochs of `channels` x `samples` (channel-major: channel c's samples at c * samples).
class ErpAccumulator {
 public:
  ErpAccumulator(int channels, int samples, int baseline_samples);
  void add(const std::vector<float>& epoch, bool target);
  // Means and standard errors (0 where an average has fewer than 2 epochs). The caller fills in
  // the names and times.
  ErpCurves curves() const;

 private:
  int channels_, samples_, baseline_samples_;
  int n_[2] = {0, 0};
  Eigen::MatrixXd sum_[2], sum_sq_[2];
};

}  // namespace arbci::bci
