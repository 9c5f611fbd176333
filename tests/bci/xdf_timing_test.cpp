// XDF stamps as a lab's recordings carry them: one stamp per sample with jitter, or per chunk as
// the chunks arrive. The reader fits the nominal rate through them and breaks the fit only where
// the stamps shift and stay shifted (a gap in the samples), so markers stamped on a sample's time
// land on that sample and the recording is as long as its signal.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "arbci/bci/recording.h"
#include "support/test_files.h"
#include "support/xdf_writer.h"

namespace arbci::bci {
namespace {

constexpr int kMarkers = 300;

struct Truth {
  test::XdfNumericStream eeg;
  test::XdfExtras extras;
  std::vector<test::XdfMarker> markers;
  std::vector<std::int64_t> marker_samples;
};

// `seconds` of 2-channel EEG at `rate`; sample s taken at t0 + s / rate (+ `gap_s` from
// `gap_at` on). Markers on 300 samples' true times.
Truth signal(double rate, double seconds, std::size_t gap_at = 0, double gap_s = 0.0) {
  Truth t;
  t.eeg.name = "Amp";
  t.eeg.rate = rate;
  t.eeg.labels = {"Cz", "Pz"};
  const auto n = static_cast<std::size_t>(rate * seconds);
  for (std::size_t s = 0; s < n; ++s)
    t.eeg.samples.push_back({static_cast<float>(s % 1000), static_cast<float>(s % 7)});
  for (int k = 0; k < kMarkers; ++k) {
    const auto s = static_cast<std::int64_t>((k + 1) * (n - 1) / (kMarkers + 1));
    const double at = t.eeg.first_timestamp + static_cast<double>(s) / rate +
                      (gap_s > 0.0 && static_cast<std::size_t>(s) >= gap_at ? gap_s : 0.0);
    t.markers.push_back({at, "flash " + std::to_string(k % 4 + 1) + " nontarget"});
    t.marker_samples.push_back(s);
  }
  return t;
}

double trueTime(const Truth& t, std::size_t s, std::size_t gap_at, double gap_s) {
  return t.eeg.first_timestamp + static_cast<double>(s) / t.eeg.rate +
         (gap_s > 0.0 && s >= gap_at ? gap_s : 0.0);
}

// One stamp per sample: its true time plus Gaussian jitter.
void jitterEachSample(Truth& t, double sd_s, unsigned seed, std::size_t gap_at = 0,
                      double gap_s = 0.0) {
  std::mt19937 random(seed);
  std::normal_distribution<double> jitter(0.0, sd_s);
  for (std::size_t s = 0; s < t.eeg.samples.size(); ++s)
    t.extras.eeg_stamps.push_back(trueTime(t, s, gap_at, gap_s) + jitter(random));
}

// LSL's chunked stamping: every `every_s` the samples taken since the last push go out as one
// chunk, stamped at the push (the last sample's time plus a delivery delay of `delay_s` plus
// up to `spread_s` more); the chunk's first sample gets that stamp less the chunk's length, the
// rest one period more each.
void stampChunks(Truth& t, double every_s, double delay_s, double spread_s, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> spread(0.0, spread_s);
  const double period = 1.0 / t.eeg.rate;
  std::size_t first = 0;
  const std::size_t n = t.eeg.samples.size();
  for (double push = t.eeg.first_timestamp + every_s; first < n; push += every_s) {
    std::size_t end = first;
    while (end < n && trueTime(t, end, 0, 0.0) <= push) ++end;
    if (end == first) continue;
    const double stamp = push + delay_s + spread(random);
    for (std::size_t s = first; s < end; ++s)
      t.extras.eeg_stamps.push_back(stamp - static_cast<double>(end - 1 - s) * period);
    first = end;
  }
}

struct Placement {
  int exact = 0;
  std::int64_t max_off = 0;
  std::int64_t worst_signed = 0;
};

Placement place(const Truth& t, const Recording& r) {
  Placement p;
  EXPECT_EQ(r.stimuli.size(), static_cast<std::size_t>(kMarkers));
  for (std::size_t k = 0; k < r.stimuli.size() && k < t.marker_samples.size(); ++k) {
    const std::int64_t off = r.stimuli[k].sample - t.marker_samples[k];
    if (off == 0) ++p.exact;
    if (std::llabs(off) > p.max_off) {
      p.max_off = std::llabs(off);
      p.worst_signed = off;
    }
  }
  return p;
}

int breaks(const Recording& r) {
  int n = 0;
  for (const Annotation& a : r.annotations) n += a.text.rfind("XDF:", 0) == 0;
  return n;
}

Recording written(const Truth& t, const std::string& name) {
  const auto path = test::freshTempPath("xdf_timing", name);
  test::writeXdf(path, t.eeg, t.markers, t.extras);
  return readRecording(path);
}

struct JitterRow {
  double rate, sd_ms;
};

class XdfSampleJitter : public ::testing::TestWithParam<JitterRow> {};

// Jitter of a millisecond or more is several sample periods at 1000 Hz: stamps step back all the
// time. None of it is a break, and every marker lands on its sample.
TEST_P(XdfSampleJitter, NoBreaksAndEveryMarkerOnItsSample) {
  const JitterRow row = GetParam();
  Truth t = signal(row.rate, 60.0);
  jitterEachSample(t, row.sd_ms * 1e-3, 11);
  const Recording r = written(t, "jitter.xdf");
  EXPECT_EQ(breaks(r), 0);
  EXPECT_EQ(r.samples, static_cast<std::int64_t>(t.eeg.samples.size()));
  const Placement p = place(t, r);
  EXPECT_EQ(p.exact, kMarkers) << "worst " << p.worst_signed << " samples off";
}

INSTANTIATE_TEST_SUITE_P(LabRecorderStamps, XdfSampleJitter,
                         ::testing::Values(JitterRow{256.0, 0.5}, JitterRow{256.0, 1.5},
                                           JitterRow{1000.0, 0.5}, JitterRow{1000.0, 3.0}));

struct ChunkRow {
  double rate, every_ms;
};

class XdfChunkStamps : public ::testing::TestWithParam<ChunkRow> {};

// Chunks stamped as they arrive are late by their delivery delay, which no reader can know: the
// markers land that many samples early (here 2 ms of delay plus up to 1 ms), never more, and
// nothing is a break.
TEST_P(XdfChunkStamps, NoBreaksAndMarkersOffByNoMoreThanTheDeliveryDelay) {
  const ChunkRow row = GetParam();
  Truth t = signal(row.rate, 60.0);
  stampChunks(t, row.every_ms * 1e-3, 0.002, 0.001, 12);
  const Recording r = written(t, "chunks.xdf");
  EXPECT_EQ(breaks(r), 0);
  EXPECT_EQ(r.samples, static_cast<std::int64_t>(t.eeg.samples.size()));
  // The stamps' line lies the mean delay (2.5 ms) plus half a chunk's spread of the last
  // sample's position late.
  const auto late = static_cast<std::int64_t>(std::ceil((0.0035 + row.every_ms * 1e-3) * row.rate));
  const Placement p = place(t, r);
  EXPECT_LE(p.max_off, late);
  for (std::size_t k = 0; k < r.stimuli.size(); ++k)
    EXPECT_LE(r.stimuli[k].sample, t.marker_samples[k]) << k;  // early, never late
}

INSTANTIATE_TEST_SUITE_P(LabRecorderStamps, XdfChunkStamps,
                         ::testing::Values(ChunkRow{1000.0, 2.0}, ChunkRow{2048.0, 1.0},
                                           ChunkRow{256.0, 50.0}));

// A real gap (0.3 s without samples) among jittered stamps, with one chunk delivered 150 ms late:
// the gap is one break of its length, the late chunk none, and markers on either side of the gap
// land on their samples.
TEST(XdfTiming, ARealGapIsOneBreakOfItsLengthALateChunkIsNone) {
  const std::size_t gap_at = 20000;
  Truth t = signal(1000.0, 60.0, gap_at, 0.3);
  jitterEachSample(t, 0.5e-3, 13, gap_at, 0.3);
  for (std::size_t s = 40000; s < 40020; ++s) t.extras.eeg_stamps[s] += 0.15;
  const Recording r = written(t, "gap.xdf");
  ASSERT_EQ(breaks(r), 1);
  EXPECT_EQ(r.annotations[0].sample, static_cast<std::int64_t>(gap_at));
  EXPECT_NE(r.annotations[0].text.find("0.300 s without EEG samples"), std::string::npos)
      << r.annotations[0].text;
  EXPECT_EQ(place(t, r).exact, kMarkers);
}

// A marker a few milliseconds before the EEG's first sample is outside it: left out and counted,
// not put on sample 0.
TEST(XdfTiming, AMarkerJustBeforeTheFirstSampleIsCountedNotPutOnIt) {
  Truth t = signal(256.0, 10.0);
  t.markers.insert(t.markers.begin(), {t.eeg.first_timestamp - 0.003, "flash 1 target"});
  const Recording r = written(t, "early.xdf");
  EXPECT_EQ(r.stimuli.size(), static_cast<std::size_t>(kMarkers));
  bool counted = false;
  for (const std::string& note : r.notes)
    counted = counted || note.find("1 marker(s) before the EEG's first sample") == 0;
  EXPECT_TRUE(counted);
}

// A file closed properly where a stream that never had a sample has no footer: read, with a
// note (a stream with samples and no footer still means the file was cut).
TEST(XdfTiming, AnEmptyStreamWithoutItsFooterIsReadWithANote) {
  Truth t = signal(256.0, 5.0);
  t.extras.empty_stream = true;
  t.extras.empty_stream_footer = false;
  const Recording r = written(t, "empty_no_footer.xdf");
  EXPECT_FALSE(r.truncated);
  bool noted = false;
  for (const std::string& note : r.notes)
    noted = noted || note.find("has no samples and no footer") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A channel whose unit is not a voltage keeps its values and is named.
TEST(XdfTiming, AChannelInCountsIsNamedNotTakenAsMicrovolts) {
  Truth t = signal(256.0, 5.0);
  t.eeg.unit = "counts";
  const Recording r = written(t, "counts.xdf");
  EXPECT_EQ(r.at(0, 5), 5.0f);
  bool named = false;
  for (const std::string& note : r.notes)
    named = named || note.find("Cz (\"counts\")") != std::string::npos;
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace arbci::bci
