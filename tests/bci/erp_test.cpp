// What the ERP outputs say of themselves: the scalp map's time is the difference's peak inside
// its search window, never the epoch's edge where drift grows; a time given is taken as given;
// the filter and the reference are stated in full.
#include <gtest/gtest.h>

#include <cmath>

#include "arbci/bci/erp.h"

namespace arbci::bci {
namespace {

// -100 to 800 ms at 256 Hz, three 10-20 channels: a P300-like difference of 3 uV at 400 ms and a
// drift that grows to 8 uV at the epoch's last sample.
ErpCurves drifting() {
  ErpCurves erp;
  erp.channels = {"Cz", "Pz", "Oz"};
  erp.rate_hz = 256.0;
  erp.start_s = -0.1;
  erp.baseline_s = 0.1;
  const int samples = static_cast<int>(0.9 * 256.0);
  erp.target_mean = Eigen::MatrixXd::Zero(3, samples);
  erp.other_mean = Eigen::MatrixXd::Zero(3, samples);
  for (int s = 0; s < samples; ++s) {
    const double t = erp.timeS(s);
    const double p300 = 3.0 * std::exp(-0.5 * std::pow((t - 0.4) / 0.05, 2));
    const double drift = t > 0.6 ? 8.0 * (t - 0.6) / (erp.timeS(samples - 1) - 0.6) : 0.0;
    for (int c = 0; c < 3; ++c) erp.target_mean(c, s) = p300 + drift;
  }
  return erp;
}

TEST(ScalpMap, DrawnAtThePeakInsideItsWindowNotAtTheDriftingEdge) {
  const ErpCurves erp = drifting();
  EXPECT_EQ(erp.peakSample(), erp.samples() - 1);  // over the whole epoch: the edge
  const auto map = scalpMapAt(erp);
  ASSERT_TRUE(map);
  EXPECT_NEAR(map->time_s, 0.4, 0.5 / 256.0);
  ScalpTime given;
  given.at_s = 0.3;
  EXPECT_NEAR(erp.timeS(scalpSample(erp, given)), 0.3, 0.5 / 256.0);
  ScalpTime outside;  // a window the epoch does not reach: the whole epoch
  outside.from_s = 2.0;
  outside.to_s = 3.0;
  EXPECT_EQ(scalpSample(erp, outside), erp.samples() - 1);
}

TEST(ErpCurves, TheFilterAndTheReferenceAreStatedInFull) {
  ErpCurves erp;
  EXPECT_EQ(erp.filterText(), "unfiltered");
  EXPECT_EQ(erp.referenceText(), "as recorded");
  erp.highpass_hz = 0.5;
  erp.lowpass_hz = 20.0;
  erp.filter_order = 4;
  erp.notch_hz = 50.0;
  erp.notch_q = 30.0;
  erp.zero_phase = true;
  erp.common_average = true;
  EXPECT_EQ(erp.filterText(),
            "4th-order Butterworth 0.5-20 Hz band-pass, 50 Hz notch (Q 30), zero-phase");
  EXPECT_EQ(erp.referenceText(), "common average");
  erp.filter_order = 2;
  erp.notch_hz = 0.0;
  EXPECT_EQ(erp.filterText(), "2nd-order Butterworth 0.5-20 Hz band-pass, zero-phase");
}

}  // namespace
}  // namespace arbci::bci
