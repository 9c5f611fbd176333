// Filters, decimation, epochs, the ring buffer and file replay, block by block as the cycle runs
// them.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "arbci/bci/epocher.h"
#include "arbci/bci/file_source.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/ring_buffer.h"
#include "support/shared_data.h"

namespace arbci::bci {
namespace {

Block noise(int channels, int samples, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> normal(0.0f, 20.0f);
  Block b(0, channels, samples);
  for (float& v : b.data) v = normal(random);
  return b;
}

Block slice(const Block& whole, int first, int count) {
  Block b(whole.first_sample + first, whole.channels, count);
  for (int c = 0; c < whole.channels; ++c) {
    for (int s = 0; s < count; ++s) b.at(c, s) = whole.at(c, first + s);
  }
  return b;
}

SignalInfo eightChannels() {
  SignalInfo info;
  info.rate_hz = 256.0;
  info.block_size = 15;
  info.channels = {"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"};
  return info;
}

// Common average, 0.5-30 Hz, a 50 Hz notch.
FilterSettings wideBand() {
  FilterSettings f;
  f.common_average = true;
  f.highpass_hz = 0.5;
  f.lowpass_hz = 30.0;
  f.order = 4;
  f.notch_hz = 50.0;
  f.notch_q = 25.0;
  return f;
}

TEST(Filters, BlockwiseOutputEqualsWholeSignalOutput) {
  const Block input = noise(8, 3000, 1);
  Block whole = input;
  FilterChain(wideBand(), eightChannels()).process(whole);
  FilterChain blockwise(wideBand(), eightChannels());
  std::mt19937 random(5);
  for (int first = 0; first < input.samples;) {
    const int count = std::min(input.samples - first, 1 + static_cast<int>(random() % 40));
    Block part = slice(input, first, count);
    blockwise.process(part);
    for (int c = 0; c < 8; ++c) {
      for (int s = 0; s < count; ++s) ASSERT_EQ(part.at(c, s), whole.at(c, first + s));
    }
    first += count;
  }
}

TEST(Filters, PassBandKeptStopBandAndLineRemoved) {
  const FilterChain chain(wideBand(), eightChannels());
  EXPECT_NEAR(chain.magnitude(5.0), 1.0, 0.02);
  EXPECT_NEAR(chain.magnitude(10.0), 1.0, 0.02);
  EXPECT_LT(chain.magnitude(50.0), 0.001);                   // notch and low-pass: below -60 dB
  EXPECT_LT(chain.magnitude(0.05), 0.01);                    // drifts
  EXPECT_NEAR(chain.magnitude(30.0), std::sqrt(0.5), 0.02);  // -3 dB at the cut-off
  EXPECT_NEAR(magnitudeResponse({notchFilter(60.0, 25.0, 256.0)}, 60.0, 256.0), 0.0, 1e-9);

  // A 50 Hz sine on top of a 6 Hz one: after the chain only the 6 Hz remains.
  Block b(0, 8, 2560);
  for (int c = 0; c < 8; ++c) {
    for (int s = 0; s < b.samples; ++s) {
      const double t = s / 256.0;
      b.at(c, s) = static_cast<float>((c + 1) * std::sin(2 * std::numbers::pi * 6 * t) +
                                      10 * std::sin(2 * std::numbers::pi * 50 * t));
    }
  }
  FilterSettings settings;
  settings.common_average = false;
  FilterChain(settings, eightChannels()).process(b);
  auto amplitude = [&](double frequency) {  // over the last 5 s, after the filter has settled
    std::complex<double> sum = 0.0;
    for (int s = 1280; s < b.samples; ++s)
      sum += double(b.at(2, s)) * std::polar(1.0, -2 * std::numbers::pi * frequency * s / 256.0);
    return 2.0 * std::abs(sum) / 1280.0;
  };
  EXPECT_NEAR(amplitude(6.0), 3.0, 0.05);
  EXPECT_LT(amplitude(50.0), 0.01);
}

// A DC-coupled amplifier's offset (1 mV, 50 mV) with a slow drift on top: the chain starts in
// the offset's steady state, so the output is the noise band-passed, never a start-up ringing.
TEST(Filters, AnOffsetAtTheStartRingsNowhere) {
  FilterSettings settings = wideBand();
  settings.common_average = false;
  const Block clean = noise(8, 2560, 3);
  Block reference = clean;
  FilterChain(settings, eightChannels()).process(reference);
  for (const double offset_uv : {1000.0, 50000.0}) {
    Block shifted = clean;
    for (int c = 0; c < 8; ++c) {
      for (int s = 0; s < shifted.samples; ++s)
        shifted.at(c, s) += static_cast<float>(offset_uv * (c % 2 ? -1 : 1) + 20.0 * s / 256.0);
    }
    FilterChain(settings, eightChannels()).process(shifted);
    double largest = 0.0;
    for (int c = 0; c < 8; ++c) {
      for (int s = 0; s < shifted.samples; ++s)
        largest = std::max(largest, std::abs(double(shifted.at(c, s) - reference.at(c, s))));
    }
    // What is left is the drift's ramp through the high-pass (its step response to a slope of
    // 20 uV/s settles below a few microvolts) and float rounding of the offset.
    EXPECT_LT(largest, 10.0) << offset_uv << " uV";
  }
}

TEST(Filters, CommonAverageReferenceLeavesZeroMean) {
  Block b = noise(8, 100, 2);
  commonAverageReference(b);
  for (int s = 0; s < b.samples; ++s) {
    double sum = 0.0;
    for (int c = 0; c < 8; ++c) sum += b.at(c, s);
    EXPECT_NEAR(sum, 0.0, 1e-3);
  }
}

TEST(Filters, BadSettingsAreNamed) {
  FilterSettings settings;
  settings.lowpass_hz = 200.0;
  try {
    FilterChain(settings, eightChannels());
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("low-pass"), std::string::npos);
  }
}

TEST(Decimator, AveragesGroupsAcrossBlockBoundaries) {
  Block ramp(0, 1, 100);
  for (int s = 0; s < 100; ++s) ramp.at(0, s) = static_cast<float>(s);
  Decimator decimator(12, 1);
  std::vector<Block> outputs;
  for (int first = 0; first < 100; first += 15)
    outputs.push_back(decimator.process(slice(ramp, first, std::min(15, 100 - first))));
  std::vector<float> values;
  std::int64_t expected_index = 0;
  for (const Block& o : outputs) {
    if (o.samples > 0) {
      EXPECT_EQ(o.first_sample, expected_index);
    }
    expected_index += o.samples;
    for (int s = 0; s < o.samples; ++s) values.push_back(o.at(0, s));
  }
  ASSERT_EQ(values.size(), 8u);  // 96 of the 100 samples form whole groups
  for (size_t k = 0; k < values.size(); ++k) EXPECT_FLOAT_EQ(values[k], 12.0f * k + 5.5f);
}

TEST(Epocher, CutsEachWindowAsSoonAsItsLastSampleArrives) {
  Block ramp(0, 2, 2000);
  for (int s = 0; s < 2000; ++s) {
    ramp.at(0, s) = static_cast<float>(s);
    ramp.at(1, s) = static_cast<float>(-s);
  }
  Epocher epocher(2, 256.0, EpochWindow{0.0, 0.8});
  ASSERT_EQ(epocher.samplesPerEpoch(), 205);
  epocher.addEvent({100, 3, true, 15});
  epocher.addEvent({150, 4, false, 15});
  int completed_at = -1;
  std::vector<Epoch> epochs;
  for (int first = 0; first < 2000; first += 15) {
    for (Epoch& e : epocher.push(slice(ramp, first, std::min(15, 2000 - first)))) {
      if (completed_at < 0) completed_at = first + 15;
      epochs.push_back(std::move(e));
    }
    if (first == 600) epocher.addEvent({400, 1, false, 15});  // late, but still in the history
  }
  ASSERT_EQ(epochs.size(), 3u);
  EXPECT_EQ(completed_at, 315);  // the block holding sample 304, the first epoch's last
  EXPECT_EQ(epochs[0].event.code, 3);
  EXPECT_EQ(epochs[0].at(0, 0), 100.0f);
  EXPECT_EQ(epochs[0].at(0, 204), 304.0f);
  EXPECT_EQ(epochs[0].at(1, 10), -110.0f);
  EXPECT_EQ(epochs[2].at(0, 0), 400.0f);
  EXPECT_EQ(epocher.missed(), 0);
  epocher.addEvent({1500, 2, false, 15});  // after its samples, within the 5 s history
  EXPECT_EQ(epocher.completed().size(), 1u);
  EXPECT_EQ(epocher.missed(), 0);
}

TEST(Epocher, EventsOlderThanTheHistoryAreCountedAsMissed) {
  Epocher epocher(1, 256.0, EpochWindow{0.0, 0.8}, 2.0);
  Block b(0, 1, 256 * 4);
  epocher.push(b);
  epocher.addEvent({10, 1, false, 15});
  EXPECT_EQ(epocher.missed(), 1);
  EXPECT_TRUE(epocher.completed().empty());
}

TEST(RingBuffer, SlowReaderIsToldHowManySamplesItLost) {
  RingBuffer ring(2, 100);
  auto fast = ring.reader(), slow = ring.reader();
  Block ramp(0, 2, 15);
  for (int block = 0; block < 10; ++block) {
    ramp.first_sample = block * 15;
    for (int s = 0; s < 15; ++s) ramp.at(0, s) = static_cast<float>(block * 15 + s);
    ring.write(ramp);
    const RingBuffer::Read r = fast.read(1000);
    EXPECT_EQ(r.lost, 0);
    EXPECT_EQ(r.block.samples, 15);
    EXPECT_EQ(r.block.at(0, 0), block * 15.0f);
  }
  const RingBuffer::Read late = slow.read(1000);
  EXPECT_EQ(late.lost, 50);  // 150 written, 100 kept
  EXPECT_EQ(late.block.first_sample, 50);
  EXPECT_EQ(late.block.samples, 100);
  EXPECT_EQ(late.block.at(0, 0), 50.0f);
  ramp.first_sample = 200;  // a gap in the clock
  EXPECT_THROW(ring.write(ramp), std::invalid_argument);
}

TEST(FileSource, ReplaysEverySampleAndStimulusPacedByItsClock) {
  Recording r = readRecording(test::sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"));
  const Recording copy = r;
  auto clock = std::make_shared<ManualClock>();
  FileSource source(std::move(r), clock, 15);
  EXPECT_TRUE(source.poll().empty());
  clock->advanceTo(10.0);
  std::int64_t delivered = 0;
  size_t stimuli = 0;
  while (!source.finished()) {
    for (const Block& b : source.poll()) {
      ASSERT_EQ(b.first_sample, delivered);
      EXPECT_EQ(b.at(3, 0), copy.at(3, b.first_sample));
      delivered += b.samples;
    }
    for (const StimulusEvent& e : source.takeRecordedStimuli()) {
      EXPECT_LT(e.sample, delivered);
      EXPECT_EQ(e.code, copy.stimuli[stimuli].code);
      ++stimuli;
    }
    if (delivered < copy.samples) {
      EXPECT_LE(delivered, static_cast<std::int64_t>(clock->seconds() * 256));
    }
    clock->advanceTo(clock->seconds() + 10.0);
  }
  EXPECT_EQ(delivered, copy.samples);
  EXPECT_EQ(stimuli, copy.stimuli.size());
}

}  // namespace
}  // namespace arbci::bci
