// The EEG view's quality grades, on signals whose answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "arbci/bci/signal_quality.h"
#include "arbci/bci/signal_scope.h"

namespace arbci::bci {
namespace {

constexpr double kRate = 256.0;
constexpr int kTwoSeconds = 512;

// Two seconds of white noise of `sd_uv`, plus a sinusoid and a ramp.
std::vector<float> signal(double sd_uv, double sine_uv = 0.0, double sine_hz = 50.0,
                          double ramp_uv_s = 0.0, unsigned seed = 3) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sd_uv);
  std::vector<float> x(kTwoSeconds);
  for (int k = 0; k < kTwoSeconds; ++k) {
    const double t = k / kRate;
    x[static_cast<size_t>(k)] = static_cast<float>(
        noise(random) + sine_uv * std::sin(2.0 * std::numbers::pi * sine_hz * t + 0.3) +
        ramp_uv_s * t);
  }
  return x;
}

SignalQuality assess(const std::vector<float>& x) {
  return assessSignal(x.data(), static_cast<int>(x.size()), kRate);
}

TEST(SignalQuality, CleanEegIsGoodAndItsRmsIsTheNoise) {
  const SignalQuality q = assess(signal(10.0));
  EXPECT_EQ(q.grade, Grade::Good) << q.finding;
  EXPECT_NEAR(q.rms_uv, 10.0, 0.8);
  EXPECT_LT(q.line50_uv, 2.0);
  EXPECT_EQ(q.finding.rfind("RMS", 0), 0u) << q.finding;
}

TEST(SignalQuality, LineNoiseIsMeasuredAt50And60HzAndGradedWithItsThreshold) {
  const SignalQuality fifty = assess(signal(5.0, 30.0, 50.0));
  EXPECT_NEAR(fifty.line50_uv, 30.0, 1.0);
  EXPECT_EQ(fifty.grade, Grade::Bad);
  EXPECT_NE(fifty.finding.find("line noise 50 Hz"), std::string::npos) << fifty.finding;
  EXPECT_NE(fifty.finding.find("bad above 20"), std::string::npos) << fifty.finding;
  const SignalQuality sixty = assess(signal(3.0, 8.0, 60.0));
  EXPECT_NEAR(sixty.line60_uv, 8.0, 0.6);
  EXPECT_LT(sixty.line50_uv, 1.5);
  EXPECT_EQ(sixty.grade, Grade::Poor) << sixty.finding;
  EXPECT_NE(sixty.finding.find("line noise 60 Hz"), std::string::npos) << sixty.finding;
}

// Broadband noise (a loose electrode) is as strong at 50 and 60 Hz as beside them: graded by its
// RMS, never as line noise; a line on top of it is still named.
TEST(SignalQuality, BroadbandNoiseIsNotLineNoise) {
  for (unsigned seed = 1; seed <= 100; ++seed) {
    const SignalQuality broadband = assess(signal(144.0, 0.0, 50.0, 0.0, seed));
    EXPECT_EQ(broadband.grade, Grade::Bad) << broadband.finding;
    EXPECT_EQ(broadband.finding.rfind("RMS", 0), 0u)
        << "seed " << seed << ": " << broadband.finding;
  }
  const SignalQuality with_line = assess(signal(40.0, 60.0, 50.0));
  EXPECT_NE(with_line.finding.find("line noise 50 Hz"), std::string::npos) << with_line.finding;
}

TEST(SignalQuality, FlatSaturatedAndDriftingChannelsAreNamed) {
  const SignalQuality flat = assess(signal(0.1));
  EXPECT_TRUE(flat.flat);
  EXPECT_EQ(flat.grade, Grade::Bad);
  EXPECT_EQ(flat.finding.rfind("flat", 0), 0u) << flat.finding;
  std::vector<float> clipped = signal(10.0);
  clipped[100] = 6000.0f;
  const SignalQuality saturated = assess(clipped);
  EXPECT_TRUE(saturated.saturated);
  EXPECT_EQ(saturated.finding.rfind("saturated", 0), 0u) << saturated.finding;
  const SignalQuality drift = assess(signal(5.0, 0.0, 50.0, 120.0));
  EXPECT_NEAR(drift.drift_uv_s, 120.0, 5.0);
  EXPECT_EQ(drift.grade, Grade::Poor) << drift.finding;
  EXPECT_NE(drift.finding.find("uV/s"), std::string::npos) << drift.finding;
  // The trend is not counted in the RMS.
  EXPECT_NEAR(drift.rms_uv, 5.0, 0.6);
}

TEST(SignalScope, KeepsTheLastSecondsInOrderAndGradesEachChannel) {
  SignalInfo info;
  info.rate_hz = kRate;
  info.block_size = 15;
  info.channels = {"Cz", "Pz"};
  FilterSettings none;
  none.highpass_hz = none.lowpass_hz = none.notch_hz = 0.0;
  SignalScope scope(info, 4.0, none, QualityThresholds{});
  EXPECT_TRUE(scope.quality().empty());
  const std::vector<float> clean = signal(10.0, 0.0, 50.0, 0.0, 1);
  const std::vector<float> noisy = signal(5.0, 30.0, 50.0, 0.0, 2);
  std::int64_t first = 1000;  // the acquisition's indices, not from zero
  for (int repeat = 0; repeat < 3; ++repeat) {
    for (int k = 0; k + 15 <= kTwoSeconds; k += 15) {
      Block block(first, 2, 15);
      for (int s = 0; s < 15; ++s) {
        block.at(0, s) = clean[static_cast<size_t>(k + s)];
        block.at(1, s) = noisy[static_cast<size_t>(k + s)];
      }
      scope.append(block);
      first += 15;
    }
  }
  EXPECT_EQ(scope.endSample(), first);
  EXPECT_EQ(scope.capacity(), 1024);
  // The newest sample is the last one appended.
  EXPECT_FLOAT_EQ(scope.at(1, 0, false), noisy[static_cast<size_t>(kTwoSeconds / 15 * 15 - 1)]);
  std::vector<float> last;
  scope.copyLast(0, 30, false, last);
  ASSERT_EQ(last.size(), 30u);
  EXPECT_FLOAT_EQ(last.back(), scope.at(0, 0, false));
  EXPECT_FLOAT_EQ(last.front(), scope.at(0, 29, false));
  ASSERT_EQ(scope.quality().size(), 2u);
  EXPECT_EQ(scope.quality()[0].grade, Grade::Good) << scope.quality()[0].finding;
  EXPECT_EQ(scope.quality()[1].grade, Grade::Bad) << scope.quality()[1].finding;
  // Stimuli older than the scope's seconds are forgotten.
  scope.markStimulus(first - 5000);
  scope.markStimulus(first - 10);
  Block one(first, 2, 15);
  scope.append(one);
  ASSERT_EQ(scope.stimuli().size(), 1u);
  EXPECT_EQ(scope.stimuli().front(), first - 10);
}

}  // namespace
}  // namespace arbci::bci
