// The simulated subject: deterministic for a seed, paced by its clock, a parietal P3 to attended
// flashes only, alpha at the configured frequency, blinks frontal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "arbci/bci/filters.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/bci/stimulus_sequence.h"

namespace arbci::bci {
namespace {

// All samples of `seconds` from a subject, channel-major, flashing 4 stimuli (code 1 attended).
struct SimulatedRun {
  std::vector<std::vector<float>> channels;
  std::vector<StimulusEvent> flashes;
};

SimulatedRun simulate(SimulatedSubjectConfig config, double seconds, bool flash = true) {
  auto clock = std::make_shared<ManualClock>();
  SimulatedSubject subject(config, clock);
  subject.attend({1});
  SimulatedRun run;
  run.channels.resize(config.montage.size());
  StimulusSequencer sequencer(4, 11);
  std::vector<int> order;
  std::int64_t next = 64;
  const auto total = static_cast<std::int64_t>(seconds * config.rate_hz);
  while (subject.samplesGenerated() < total) {
    const std::int64_t end = subject.samplesGenerated() + config.block_size;
    while (flash && next < end) {
      if (order.empty()) order = sequencer.next();
      StimulusEvent e{next, order.back(), order.back() == 1, 15};
      order.pop_back();
      subject.present(e);
      run.flashes.push_back(e);
      next += static_cast<std::int64_t>(0.18 * config.rate_hz);
    }
    clock->advanceTo(end / config.rate_hz);
    for (const Block& b : subject.poll()) {
      for (int c = 0; c < b.channels; ++c) {
        for (int s = 0; s < b.samples; ++s) run.channels[c].push_back(b.at(c, s));
      }
    }
  }
  return run;
}

TEST(SimulatedSubject, SameSeedSameSignalOtherSeedOtherSignal) {
  SimulatedSubjectConfig config;
  const SimulatedRun a = simulate(config, 5.0), b = simulate(config, 5.0);
  EXPECT_EQ(a.channels, b.channels);
  config.seed = 2;
  const SimulatedRun c = simulate(config, 5.0);
  EXPECT_NE(a.channels[0], c.channels[0]);
}

TEST(SimulatedSubject, DeliversOnlyWhatItsClockAllowsInWholeBlocks) {
  auto clock = std::make_shared<ManualClock>();
  SimulatedSubject subject(SimulatedSubjectConfig{}, clock);
  EXPECT_TRUE(subject.poll().empty());
  clock->advanceTo(1.0);  // 256 samples: 17 whole blocks of 15
  const std::vector<Block> blocks = subject.poll();
  ASSERT_EQ(blocks.size(), 17u);
  EXPECT_EQ(blocks[0].first_sample, 0);
  EXPECT_EQ(blocks[16].first_sample, 240);
  EXPECT_EQ(blocks[16].samples, 15);
  EXPECT_TRUE(subject.poll().empty());
  clock->advanceTo(2.0);
  EXPECT_EQ(subject.poll(3).size(), 3u);  // at most what was asked
  EXPECT_EQ(subject.poll().front().first_sample, 300);
}

TEST(SimulatedSubject, TargetMinusNonTargetAtPzPeaksBetween250And500Ms) {
  SimulatedSubjectConfig config;
  const SimulatedRun run = simulate(config, 120.0);
  // Band-pass as the classifier will, then average 0-800 ms after each flash.
  SignalInfo info;
  info.rate_hz = config.rate_hz;
  info.block_size = config.block_size;
  info.channels = config.montage;
  Block all(0, static_cast<int>(config.montage.size()), static_cast<int>(run.channels[0].size()));
  for (int c = 0; c < all.channels; ++c)
    std::copy(run.channels[c].begin(), run.channels[c].end(), all.data.begin() + c * all.samples);
  FilterSettings settings;
  settings.lowpass_hz = 12.0;
  FilterChain(settings, info).process(all);
  const int pz = 3, length = 205;
  std::vector<double> target(length, 0.0), other(length, 0.0);
  int n_target = 0, n_other = 0;
  for (const StimulusEvent& e : run.flashes) {
    if (e.sample + length > all.samples) break;
    auto& sum = e.target ? target : other;
    (e.target ? n_target : n_other)++;
    for (int s = 0; s < length; ++s) sum[s] += all.at(pz, static_cast<int>(e.sample) + s);
  }
  ASSERT_GT(n_target, 100);
  int peak = 0;
  for (int s = 0; s < length; ++s) {
    if (target[s] / n_target - other[s] / n_other > target[peak] / n_target - other[peak] / n_other)
      peak = s;
  }
  const double peak_ms = peak * 1000.0 / 256.0;
  EXPECT_GE(peak_ms, 250.0);
  EXPECT_LE(peak_ms, 500.0);
  EXPECT_GT(target[peak] / n_target - other[peak] / n_other, 1.0);  // microvolts
}

// Feedback every 1.5 s, a quarter of it wrong (the subject attends code 1): the average at Cz
// after wrong minus right feedback has the ErrP's fronto-central negativity and later positivity,
// at the profile's latencies; with errp amplitudes of 0 there is none.
struct FeedbackAverages {
  std::vector<double> difference;  // Cz, wrong minus right, 0-800 ms, 12 Hz low-passed
  int wrong = 0, right = 0;
};

FeedbackAverages feedbackAverages(const SimulatedSubjectConfig& config) {
  auto clock = std::make_shared<ManualClock>();
  SimulatedSubject subject(config, clock);
  subject.attend({1});
  std::vector<std::pair<std::int64_t, bool>> feedbacks;  // onset, wrong
  std::vector<std::vector<float>> channels(config.montage.size());
  std::int64_t next = 128;
  const auto total = static_cast<std::int64_t>(900.0 * config.rate_hz);
  while (subject.samplesGenerated() < total) {
    const std::int64_t end = subject.samplesGenerated() + config.block_size;
    while (next < end) {
      const bool wrong = feedbacks.size() % 4 == 1;
      subject.feedback(next, {wrong ? 3 : 1});
      feedbacks.emplace_back(next, wrong);
      next += static_cast<std::int64_t>(1.5 * config.rate_hz);
    }
    clock->advanceTo(end / config.rate_hz);
    for (const Block& b : subject.poll()) {
      for (int c = 0; c < b.channels; ++c)
        for (int s = 0; s < b.samples; ++s) channels[c].push_back(b.at(c, s));
    }
  }
  SignalInfo info;
  info.rate_hz = config.rate_hz;
  info.block_size = config.block_size;
  info.channels = config.montage;
  Block all(0, static_cast<int>(channels.size()), static_cast<int>(channels[0].size()));
  for (int c = 0; c < all.channels; ++c)
    std::copy(channels[c].begin(), channels[c].end(), all.data.begin() + c * all.samples);
  FilterSettings settings;
  settings.common_average = false;  // the ErrP is everywhere: a common average would halve it
  settings.lowpass_hz = 12.0;
  FilterChain(settings, info).process(all);
  const int cz = 1, length = 205;
  FeedbackAverages out;
  std::vector<double> wrong(length, 0.0), right(length, 0.0);
  for (const auto& [onset, is_wrong] : feedbacks) {
    if (onset + length > all.samples) break;
    (is_wrong ? out.wrong : out.right)++;
    for (int s = 0; s < length; ++s)
      (is_wrong ? wrong : right)[s] += all.at(cz, static_cast<int>(onset) + s);
  }
  for (int s = 0; s < length; ++s)
    out.difference.push_back(wrong[s] / out.wrong - right[s] / out.right);
  return out;
}

TEST(SimulatedSubject, WrongFeedbackEvokesAFrontoCentralNegativityThenPositivity) {
  SimulatedSubjectConfig config;
  config.blinks_per_minute = 0.0;
  const SubjectProfile profile = SubjectProfile::drawn(config.seed);
  const FeedbackAverages a = feedbackAverages(config);
  ASSERT_GT(a.wrong, 140);
  const auto low = std::min_element(a.difference.begin(), a.difference.begin() + 103);
  const auto high = std::max_element(a.difference.begin(), a.difference.end());
  const double low_ms = (low - a.difference.begin()) * 1000.0 / 256.0;
  const double high_ms = (high - a.difference.begin()) * 1000.0 / 256.0;
  // The filters delay a little; the components overlap, so the peaks move apart a little.
  EXPECT_NEAR(low_ms, 1000.0 * profile.errp_ne_latency_s, 60.0);
  EXPECT_NEAR(high_ms, 1000.0 * profile.errp_pe_latency_s, 60.0);
  EXPECT_LT(*low, -1.5);  // microvolts
  EXPECT_GT(*high, 2.0);
  EXPECT_LT(low_ms, high_ms);

  SubjectProfile none = profile;
  none.errp_ne_amplitude_uv = none.errp_pe_amplitude_uv = 0.0;
  config.profile = none;
  const FeedbackAverages b = feedbackAverages(config);
  for (double v : b.difference) EXPECT_LT(std::abs(v), 1.5);
}

// Power at `frequency` by a Goertzel-like projection, averaged over 2 s windows.
double power(const std::vector<float>& x, double frequency, double rate) {
  const int window = static_cast<int>(2 * rate);
  double total = 0.0;
  int windows = 0;
  for (size_t start = 0; start + window <= x.size(); start += window, ++windows) {
    std::complex<double> sum = 0.0;
    for (int n = 0; n < window; ++n) {
      const double hann = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * n / window);
      sum += hann * x[start + n] * std::polar(1.0, -2.0 * std::numbers::pi * frequency * n / rate);
    }
    total += std::norm(sum);
  }
  return total / windows;
}

TEST(SimulatedSubject, AlphaPeaksAtTheConfiguredFrequencyOccipitally) {
  for (double alpha : {9.0, 11.5}) {
    SimulatedSubjectConfig config;
    config.alpha_hz = alpha;
    config.blinks_per_minute = 0.0;
    const SimulatedRun run = simulate(config, 60.0, false);
    const int oz = 6;
    double best = 0.0, best_power = 0.0;
    for (double f = 6.0; f <= 14.0; f += 0.5) {
      const double p = power(run.channels[oz], f, 256.0);
      if (p > best_power) {
        best_power = p;
        best = f;
      }
    }
    EXPECT_NEAR(best, alpha, 0.5);
    // Background is 1/f: more power at 4 Hz than at 25 Hz.
    EXPECT_GT(power(run.channels[0], 4.0, 256.0), 3.0 * power(run.channels[0], 25.0, 256.0));
  }
}

TEST(SimulatedSubject, LineNoiseAndFrontalBlinks) {
  SimulatedSubjectConfig config;
  config.blinks_per_minute = 30.0;
  const SimulatedRun run = simulate(config, 30.0, false);
  EXPECT_GT(power(run.channels[6], 50.0, 256.0), 10.0 * power(run.channels[6], 45.0, 256.0));
  auto peak = [](const std::vector<float>& x) {
    double m = 0.0;
    for (float v : x) m = std::max(m, std::abs(double(v)));
    return m;
  };
  EXPECT_GT(peak(run.channels[0]), 2.0 * peak(run.channels[6]));  // Fz against Oz
}

TEST(SimulatedSubject, RefusesAnEmptyMontage) {
  SimulatedSubjectConfig config;
  config.montage.clear();
  EXPECT_THROW(SimulatedSubject(config, std::make_shared<UnboundedClock>()), std::invalid_argument);
}

}  // namespace
}  // namespace arbci::bci
