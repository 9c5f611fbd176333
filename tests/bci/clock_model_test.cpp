// The EEG clock as the time base: the clock model against an amplifier whose clock runs 200 ppm
// fast with late, jittered arrivals, and the acquisition's lock-step, gap, overflow and live paths
// with the simulated subject's virtual photodiode.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>
#include <thread>

#include "arbci/bci/acquisition.h"
#include "arbci/bci/clock_model.h"
#include "arbci/bci/simulated_subject.h"

namespace arbci::bci {
namespace {

TEST(ClockModel, StampsStayWithinOneSampleOfAClock200PpmFastOverTenMinutes) {
  const double nominal = 256.0, true_rate = 256.0 * (1.0 + 200e-6);
  const double latency = 0.004;  // known (measured) part of the delivery delay
  ClockModel model(nominal, 120.0, latency);
  std::mt19937_64 random(7);
  std::exponential_distribution<double> late(1.0 / 0.0008);  // USB scheduling: mean 0.8 ms late
  std::uniform_real_distribution<double> instant(0.0, 1.0);
  const double t0 = 5000.0;  // host time of sample 0
  int checked = 0, worst = 0;
  double worst_drift_error = 0.0;
  for (std::int64_t end = 15; end <= static_cast<std::int64_t>(600 * true_rate); end += 15) {
    model.observe(end, t0 + end / true_rate + latency + late(random));
    if (end < static_cast<std::int64_t>(10 * true_rate)) continue;  // warming up
    // A host instant within this block: which sample was taken then?
    const double host = t0 + (end - 15 * instant(random)) / true_rate;
    const auto truth = static_cast<std::int64_t>(std::ceil((host - t0) * true_rate - 1e-9));
    const auto error = static_cast<int>(std::llabs(model.firstSampleAtOrAfter(host) - truth));
    worst = std::max(worst, error);
    ++checked;
    if (end > static_cast<std::int64_t>(60 * true_rate))
      worst_drift_error = std::max(worst_drift_error, std::abs(model.driftPpm() - 200.0));
  }
  EXPECT_GT(checked, 9000);
  EXPECT_LE(worst, 1) << "a stamp more than one sample from the truth";
  EXPECT_LT(worst_drift_error, 20.0) << "fitted drift " << model.driftPpm() << " ppm";
  EXPECT_NEAR(model.driftPpm(), 200.0, 20.0);
  EXPECT_GT(model.jitterS(), 0.0003);  // the arrival jitter is reported, not hidden
  EXPECT_LT(model.jitterS(), 0.002);
}

// Not the arrival pattern the envelope was chosen on: an amplifier 150 ppm slow whose USB
// transfers carry four blocks at a time (each block up to 176 ms late), with 1 % of transfers held
// a further 20 ms by the host's scheduler.
TEST(ClockModel, BurstyArrivalsFromASlowClockStayWithinOneSample) {
  const double true_rate = 256.0 * (1.0 - 150e-6);
  ClockModel model(256.0);
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double t0 = 100.0;
  int worst = 0;
  for (std::int64_t end = 60; end <= static_cast<std::int64_t>(600 * true_rate); end += 60) {
    // One transfer: four 15-sample blocks, all arriving once the last is complete.
    const double stall = unit(random) < 0.01 ? 0.020 : 0.0;
    const double arrival = t0 + end / true_rate + 0.0005 * unit(random) + stall;
    for (std::int64_t block_end = end - 45; block_end <= end; block_end += 15)
      model.observe(block_end, arrival);
    if (end < static_cast<std::int64_t>(30 * true_rate)) continue;
    const double host = t0 + (end - 60 * unit(random)) / true_rate;
    const auto truth = static_cast<std::int64_t>(std::ceil((host - t0) * true_rate - 1e-9));
    worst = std::max(worst, static_cast<int>(std::llabs(model.firstSampleAtOrAfter(host) - truth)));
  }
  EXPECT_LE(worst, 1);
  EXPECT_NEAR(model.driftPpm(), -150.0, 20.0);
}

// What a source stamped by arrival gives the model: each delivery's blocks share the instant the
// delivery arrived. The amplifier runs `drift_ppm` fast, deliveries come every block, 0.8 ms late
// on average; `held` says for which stretches of sample time deliveries are held up (a stall: the
// blocks queue and arrive together when it ends), `drain_each_block` that a held-up queue drains
// block by block (one delivery each, 1 ms apart) instead of at once.
struct Stall {
  double from_s, seconds;
};
struct Replay {
  int worst_after = 0;       // the worst stamp error (samples) from 5 s after each disturbance on
  double drift_error = 0.0;  // the worst |drift - truth| while the model called it reliable
  int stalls = 0;            // observations the model called stalls
};
Replay replay(double drift_ppm, double startup_backlog_s, const std::vector<Stall>& stalls,
              bool drain_each_block, std::uint64_t seed) {
  const double true_rate = 256.0 * (1.0 + drift_ppm * 1e-6);
  ClockModel model(256.0);
  std::mt19937_64 random(seed);
  std::exponential_distribution<double> late(1.0 / 0.0008);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double t0 = 1000.0;
  Replay out;
  std::vector<std::int64_t> queue;  // block ends waiting to be delivered
  double settled_after = startup_backlog_s + 5.0;
  auto held = [&](double t) {
    for (const Stall& s : stalls)
      if (t >= s.from_s && t < s.from_s + s.seconds) return true;
    return false;
  };
  for (std::int64_t end = 15; end <= static_cast<std::int64_t>(300 * true_rate); end += 15) {
    const double complete = end / true_rate;  // sample time when the block is complete
    queue.push_back(end);
    if (complete < startup_backlog_s || held(complete)) continue;
    for (const Stall& s : stalls)
      if (complete >= s.from_s + s.seconds && complete < s.from_s + s.seconds + 0.1)
        settled_after = std::max(settled_after, s.from_s + s.seconds + 5.0);
    const double arrival = t0 + complete + late(random);
    for (size_t i = 0; i < queue.size(); ++i) {
      // Drained block by block: the older blocks of the queue 1 ms apart, before this one.
      const double at =
          drain_each_block ? arrival - 0.001 * static_cast<double>(queue.size() - 1 - i) : arrival;
      out.stalls += model.observe(queue[i], std::max(at, t0 + queue[i] / true_rate)).stall;
    }
    queue.clear();
    if (complete < settled_after) continue;
    const double host = t0 + (end - 15 * unit(random)) / true_rate;
    const auto truth = static_cast<std::int64_t>(std::ceil((host - t0) * true_rate - 1e-9));
    out.worst_after = std::max(
        out.worst_after, static_cast<int>(std::llabs(model.firstSampleAtOrAfter(host) - truth)));
    if (model.driftReliable())
      out.drift_error = std::max(out.drift_error, std::abs(model.driftPpm() - drift_ppm));
  }
  return out;
}

TEST(ClockModel, AStartUpBacklogAndAFiveSecondStallLeaveTheStampsWithinOneSampleAfterFiveSeconds) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const Replay r = replay(60.0, 2.0, {{60.0, 5.0}, {150.0, 2.0}}, false, seed);
    EXPECT_LE(r.worst_after, 1) << "seed " << seed;
    EXPECT_LE(r.drift_error, 20.0) << "seed " << seed;
  }
}

TEST(ClockModel, AStallDrainedBlockByBlockIsReportedAndNotFitted) {
  const Replay r = replay(-80.0, 0.0, {{40.0, 2.0}, {120.0, 5.0}}, true, 4);
  EXPECT_LE(r.worst_after, 1);
  EXPECT_LE(r.drift_error, 20.0);
  EXPECT_GT(r.stalls, 20);  // the blocks that waited more than the late limit
}

TEST(ClockModel, ANominalRateFarFromTheTruthIsHeldAtTheBoundAndCalledUnreliable) {
  ClockModel model(256.0);
  const double true_rate = 256.0 * 1.002;  // 2000 ppm: a wrong nominal rate, not a crystal
  for (std::int64_t end = 15; end < 60 * 256; end += 15) model.observe(end, end / true_rate);
  EXPECT_TRUE(model.driftAtBound());
  EXPECT_FALSE(model.driftReliable());
  EXPECT_NEAR(model.driftPpm(), ClockModel::kMaxDriftPpm, 1.0);
}

TEST(ClockModel, DriftIsNotCalledReliableOnAFewSecondsOfJitteredArrivals) {
  ClockModel model(256.0);
  std::mt19937_64 random(9);
  std::exponential_distribution<double> late(1.0 / 0.004);  // a jittery USB path: 4 ms mean
  for (std::int64_t end = 15; end < 3 * 256; end += 15)
    model.observe(end, end / 256.0 + late(random));
  EXPECT_FALSE(model.driftReliable()) << model.driftUncertaintyPpm() << " ppm";
}

TEST(ClockModel, RefusesNonsense) {
  EXPECT_THROW(ClockModel(0.0), std::invalid_argument);
  EXPECT_THROW(ClockModel(256.0, -1.0), std::invalid_argument);
}

// A source that numbers its blocks with a gap (a lost USB transfer) after the fourth block.
class GappySource final : public EegSource {
 public:
  explicit GappySource(std::shared_ptr<const SampleClock> clock) : clock_(std::move(clock)) {
    info_.channels = {"Cz"};
    info_.rate_hz = 256.0;
    info_.block_size = 15;
  }
  const SignalInfo& info() const override { return info_; }
  std::vector<Block> poll(int) override {
    std::vector<Block> out;
    while (next_ + 15 <= clock_->available(256.0)) {
      if (blocks_++ != 4) {
        Block b(next_, 1, 15);
        for (int s = 0; s < 15; ++s) b.at(0, s) = 1.0f;
        out.push_back(b);
      }
      next_ += 15;
    }
    return out;
  }

 private:
  SignalInfo info_;
  std::shared_ptr<const SampleClock> clock_;
  std::int64_t next_ = 0;
  int blocks_ = 0;
};

// An amplifier 62 ppm fast, 60 s, then a gap whose length was counted one sample long (a
// reconnected LSL stream counts it from the stamps either side): the samples after it sit one
// sample off the old line. Fitted across the step, the drift is far off and looks sure of itself;
// started again at the gap, it is unreliable at first, then right.
TEST(ClockModel, AGapStartsTheFitAgainSoAStepInTheCountCannotBendTheDrift) {
  auto run = [](bool start_again) {
    ClockModel model(256.0, 120.0);
    const double rate = 256.0 * (1.0 + 62e-6);
    std::int64_t end = 0;
    double off = 0.0;  // samples the count is ahead of the truth
    auto deliver = [&] {
      end += 16;
      model.observe(end, (static_cast<double>(end) - off) / rate);
    };
    for (int k = 0; k < 960; ++k) deliver();  // 60 s
    end += 256 * 5;  // 5 s away; the count says one sample more than was missed
    off = 1.0;
    if (start_again) model.startAgain();
    deliver();
    const bool reliable_at_once = model.driftReliable();
    for (int k = 0; k < 480; ++k) deliver();  // 30 s more
    return std::make_pair(reliable_at_once, model.driftPpm());
  };
  const auto [bent_reliable, bent] = run(false);
  EXPECT_GT(std::abs(bent - 62.0), 10.0) << bent;  // what a step does to a fit across it
  const auto [reliable_at_once, drift] = run(true);
  EXPECT_FALSE(reliable_at_once);
  EXPECT_NEAR(drift, 62.0, 1.0);
}

TEST(Acquisition, AGapIsFilledWithZerosCountedAndNamed) {
  auto clock = std::make_shared<ManualClock>();
  Acquisition acquisition(std::make_unique<GappySource>(clock), clock, Acquisition::Mode::Stepped);
  acquisition.advanceTo(1.0);
  std::int64_t next = 0, zeros = 0;
  for (const Block& b : acquisition.take()) {
    EXPECT_EQ(b.first_sample, next);
    next = b.endSample();
    for (float v : b.data) zeros += v == 0.0f;
  }
  EXPECT_EQ(next, 255);
  EXPECT_EQ(zeros, 15);
  EXPECT_EQ(acquisition.lostSamples(), 15);
  const auto losses = acquisition.takeLosses();
  ASSERT_EQ(losses.size(), 1u);
  EXPECT_EQ(losses[0].first_sample, 60);
  EXPECT_EQ(losses[0].samples, 15);
}

TEST(Acquisition, ACycleThatFallsBehindLosesTheOldestAndSaysHowMany) {
  auto clock = std::make_shared<ManualClock>();
  SimulatedSubjectConfig config;
  AcquisitionSettings settings;
  settings.queue_s = 0.5;
  Acquisition acquisition(std::make_unique<SimulatedSubject>(config, clock), clock,
                          Acquisition::Mode::Stepped, settings);
  for (int i = 1; i <= 20; ++i) acquisition.advanceTo(0.1 * i);  // 2 s, never taken
  const auto blocks = acquisition.take();
  ASSERT_FALSE(blocks.empty());
  EXPECT_EQ(blocks.front().first_sample, 0);  // the lost stretch comes back as zeros
  std::int64_t next = 0;
  for (const Block& b : blocks) {
    EXPECT_EQ(b.first_sample, next);
    next = b.endSample();
  }
  EXPECT_EQ(next, 510);
  EXPECT_GE(acquisition.lostSamples(), 510 - 128 - 15);
  EXPECT_LE(acquisition.lostSamples(), 510 - 128 + 15);
  EXPECT_FALSE(acquisition.takeLosses().empty());
}

TEST(Acquisition, SteppedStampsAreExactAndTheSameEveryRun) {
  auto run = [] {
    auto clock = std::make_shared<ManualClock>();
    SimulatedSubjectConfig config;
    config.photodiode = true;
    Acquisition acquisition(std::make_unique<SimulatedSubject>(config, clock), clock,
                            Acquisition::Mode::Stepped);
    std::vector<float> all;
    for (int frame = 1; frame <= 120; ++frame) {
      acquisition.advanceTo(frame / 60.0);
      if (frame == 30) acquisition.withSource([](EegSource& s) { s.displayed(30 / 60.0, true); });
      for (const Block& b : acquisition.take()) all.insert(all.end(), b.data.begin(), b.data.end());
    }
    EXPECT_EQ(acquisition.firstSampleAtOrAfter(0.5), 128);
    EXPECT_EQ(acquisition.firstSampleAtOrAfter(30 / 60.0 + 1e-4), 129);
    EXPECT_DOUBLE_EQ(acquisition.driftPpm(), 0.0);
    return all;
  };
  EXPECT_EQ(run(), run());
}

// One channel, Cz, at 256 Hz, in blocks of `block_size`: the test sources below.
class OneChannelSource : public EegSource {
 public:
  explicit OneChannelSource(int block_size) {
    info_.channels = {"Cz"};
    info_.rate_hz = 256.0;
    info_.block_size = block_size;
  }
  const SignalInfo& info() const override { return info_; }

 private:
  SignalInfo info_;
};

// A source that sends some samples twice: its third delivery overlaps the second by 5 samples,
// its fourth repeats the first outright.
class RepeatingSource final : public OneChannelSource {
 public:
  RepeatingSource() : OneChannelSource(15) {}
  std::vector<Block> poll(int) override {
    std::vector<Block> out;
    const std::int64_t firsts[] = {0, 15, 25, 0, 40};
    if (call_ < 5) {
      Block b(firsts[call_], 1, 15);
      for (int s = 0; s < 15; ++s) b.at(0, s) = static_cast<float>(b.first_sample + s);
      out.push_back(b);
    }
    ++call_;
    return out;
  }

 private:
  int call_ = 0;
};

TEST(Acquisition, OverlappingAndRepeatedBlocksAreTrimmedAndCountedNeverThrown) {
  auto clock = std::make_shared<ManualClock>();
  Acquisition acquisition(std::make_unique<RepeatingSource>(), clock, Acquisition::Mode::Stepped);
  for (int i = 1; i <= 6; ++i) EXPECT_NO_THROW(acquisition.advanceTo(0.1 * i));
  std::vector<float> values;
  for (const Block& b : acquisition.take())
    values.insert(values.end(), b.data.begin(), b.data.end());
  ASSERT_EQ(values.size(), 55u);  // samples 0 to 54, each once, in order
  for (size_t i = 0; i < values.size(); ++i) EXPECT_EQ(values[i], static_cast<float>(i));
  EXPECT_EQ(acquisition.repeatedSamples(), 5 + 15);
  EXPECT_EQ(acquisition.lostSamples(), 0);
}

// A live source that queues 2 s of signal once (a stall upstream), then delivers as usual.
class StallingSource final : public OneChannelSource {
 public:
  StallingSource() : OneChannelSource(16) {}
  std::vector<Block> poll(int) override {
    std::vector<Block> out;
    const int blocks = call_ == 3 ? 32 : call_ < 8 ? 1 : 0;  // 32 blocks: 2 s at once
    for (int i = 0; i < blocks; ++i) {
      out.emplace_back(next_, 1, 16);
      next_ += 16;
    }
    ++call_;
    return out;
  }

 private:
  int call_ = 0;
  std::int64_t next_ = 0;
};

TEST(Acquisition, ABacklogDeliveredAtOnceIsReportedAsAStallWithItsSize) {
  auto clock = std::make_shared<WallClock>(0.0);
  Acquisition acquisition(std::make_unique<StallingSource>(), clock, Acquisition::Mode::Live);
  acquisition.start();
  std::vector<DeliveryStall> stalls;
  // Bounded wait (the source is done after its eighth poll, a few milliseconds).
  for (int i = 0; i < 1000 && stalls.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    for (const DeliveryStall& s : acquisition.takeStalls()) stalls.push_back(s);
  }
  acquisition.stop();
  ASSERT_EQ(stalls.size(), 1u);
  EXPECT_EQ(stalls[0].first_sample, 48);  // after the first three single blocks
  EXPECT_EQ(stalls[0].samples, 512);
  EXPECT_LT(stalls[0].since_host_s, stalls[0].host_s);
  EXPECT_TRUE(acquisition.fault().empty());
}

TEST(Acquisition, LiveSubjectRunsOnItsOwnClockAndItsPhotodiodeRisesOnTheStampedSample) {
  auto clock = std::make_shared<WallClock>(0.02);
  SimulatedSubjectConfig config;
  config.photodiode = true;
  Acquisition acquisition(std::make_unique<SimulatedSubject>(config, clock), clock,
                          Acquisition::Mode::Live);
  acquisition.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double lit_at = hostSeconds();
  acquisition.withSource([&](EegSource& s) { s.displayed(lit_at, true); });
  const std::int64_t stamp = acquisition.firstSampleAtOrAfter(lit_at);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  acquisition.stop();
  const auto blocks = acquisition.take();
  std::int64_t rise = -1, samples = 0;
  const int diode = config.montage.size();
  for (const Block& b : blocks) {
    samples += b.samples;
    for (int s = 0; s < b.samples && rise < 0; ++s)
      if (b.at(diode, s) > 500.0f) rise = b.first_sample + s;
  }
  EXPECT_GT(samples, 120);  // about 0.7 s at 256 Hz, minus the 20 ms transport
  EXPECT_LT(samples, 256);
  ASSERT_GE(rise, 0) << "the photodiode never rose";
  EXPECT_LE(std::llabs(rise - stamp), 1) << "rise " << rise << ", stamp " << stamp;
  EXPECT_EQ(acquisition.lostSamples(), 0);
}

}  // namespace
}  // namespace arbci::bci
