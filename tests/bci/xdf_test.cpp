// XDF recordings (LabRecorder's format) read by ARBCI's own reader, from files our own test
// writer makes: every sample and event is known, including what real files hold (streams with
// no samples, string markers of several channels, clock resets, breaks, files cut short).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "arbci/bci/recording.h"
#include "support/test_files.h"
#include "support/xdf_writer.h"

namespace arbci::bci {
namespace {

test::XdfNumericStream eegStream(int samples) {
  test::XdfNumericStream s;
  s.name = "ActiChamp";
  s.labels = {"Fz", "Cz", "Pz", "Oz"};
  for (int i = 0; i < samples; ++i) {
    std::vector<float> v;
    for (int c = 0; c < 4; ++c)
      v.push_back(static_cast<float>(std::sin(i * 0.01 * (c + 1)) * 40.0 + c));
    s.samples.push_back(v);
  }
  return s;
}

TEST(Xdf, OneEegStreamAndItsMarkersReadBackWithTheRightSamplesAndEvents) {
  const auto path = test::freshTempPath("xdf", "eeg_and_markers.xdf");
  const test::XdfNumericStream eeg = eegStream(1000);
  const double t0 = eeg.first_timestamp, dt = 1.0 / eeg.rate;
  test::writeXdf(path, eeg,
                 {{t0 + 50 * dt, "Trial 1 start"},
                  {t0 + 100 * dt, "flash 3 target"},
                  {t0 + 200.4 * dt, "flash 4 nontarget"},  // between samples: the nearest
                  {t0 + 300 * dt, "7"},
                  {t0 + 2000 * dt, "flash 1 target"}});  // after the EEG ended: dropped
  const Recording r = readRecording(path);
  EXPECT_EQ(r.format, "XDF");
  EXPECT_EQ(r.info.channels, eeg.labels);
  EXPECT_DOUBLE_EQ(r.info.rate_hz, 256.0);
  ASSERT_EQ(r.samples, 1000);
  for (int s = 0; s < 1000; ++s)
    for (int c = 0; c < 4; ++c) ASSERT_EQ(r.at(c, s), eeg.samples[s][c]) << s << " " << c;
  ASSERT_EQ(r.stimuli.size(), 3u);
  EXPECT_EQ(r.stimuli[0].sample, 100);
  EXPECT_EQ(r.stimuli[0].code, 3);
  EXPECT_TRUE(r.stimuli[0].target && r.stimuli[0].known);
  EXPECT_EQ(r.stimuli[1].sample, 200);
  EXPECT_EQ(r.stimuli[1].code, 4);
  EXPECT_FALSE(r.stimuli[1].target);
  EXPECT_TRUE(r.stimuli[1].known);
  EXPECT_EQ(r.stimuli[2].sample, 300);
  EXPECT_EQ(r.stimuli[2].code, 7);
  EXPECT_FALSE(r.stimuli[2].known);
  ASSERT_EQ(r.annotations.size(), 1u);
  EXPECT_EQ(r.annotations[0].sample, 50);
  EXPECT_EQ(r.annotations[0].text, "Trial 1 start");
}

TEST(Xdf, ValuesInVoltsAreReadAsMicrovolts) {
  const auto path = test::freshTempPath("xdf", "volts.xdf");
  test::XdfNumericStream eeg = eegStream(10);
  eeg.unit = std::string(1, 'V');  // (a literal here trips GCC 12's false -Wrestrict)
  for (auto& s : eeg.samples)
    for (auto& v : s) v *= 1e-6f;
  test::writeXdf(path, eeg, {});
  const Recording r = readRecording(path);
  EXPECT_NEAR(r.at(1, 5), eeg.samples[5][1] * 1e6, 1e-3);
}

TEST(Xdf, ACorruptFileIsRefusedWithItsNameNotACrash) {
  const auto path = test::freshTempPath("xdf", "corrupt.xdf");
  std::ofstream(path, std::ios::binary) << "XDF:" << std::string("\x01\x05\x02\x00<in", 7);
  try {
    readRecording(path);
    FAIL();
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("corrupt.xdf"), std::string::npos) << e.what();
  }
}

// As the public example empty_streams.xdf: a stream with a header and not one sample.
TEST(Xdf, AStreamWithoutSamplesIsAcceptedAndAFileWithNoEegNamesItsStreams) {
  const auto path = test::freshTempPath("xdf", "empty_stream.xdf");
  test::XdfExtras extras;
  extras.empty_stream = true;
  test::writeXdf(path, eegStream(300), {{100.5, "flash 2 target"}}, extras);
  const Recording r = readRecording(path);
  EXPECT_EQ(r.samples, 300);
  EXPECT_EQ(r.info.channelCount(), 4);
  ASSERT_EQ(r.stimuli.size(), 1u);

  const auto nothing = test::freshTempPath("xdf", "no_samples.xdf");
  test::writeXdf(nothing, eegStream(0), {}, extras);
  try {
    readRecording(nothing);
    FAIL() << "a file without EEG samples was read";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("no regular numeric stream with samples"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("(\"Empty\"): 2 float32 channel(s), 100 Hz, 0 samples"),
              std::string::npos)
        << e.what();
  }
}

// Valid per the specification: a marker stream of two string channels. The first channel is the
// event; the second is kept beside it. Every marker arrives.
TEST(Xdf, StringMarkersOfTwoChannelsAreAllReadTheFirstAsTheEvent) {
  const auto path = test::freshTempPath("xdf", "two_channel_markers.xdf");
  const test::XdfNumericStream eeg = eegStream(5000);
  const double t0 = eeg.first_timestamp, dt = 1.0 / eeg.rate;
  std::vector<test::XdfMarker> markers;
  for (int i = 0; i < 120; ++i)
    markers.push_back(
        {t0 + (40 + 40 * i) * dt,
         "flash " + std::to_string(i % 6 + 1) + (i % 6 == 2 ? " target" : " nontarget"),
         {"trial " + std::to_string(i / 12 + 1)}});
  test::XdfExtras extras;
  extras.marker_channels = 2;
  test::writeXdf(path, eeg, markers, extras);
  const Recording r = readRecording(path);
  ASSERT_EQ(r.stimuli.size(), 120u);
  int details = 0;
  for (const Annotation& a : r.annotations) details += a.text.rfind("marker detail: trial", 0) == 0;
  EXPECT_EQ(details, 120);
  for (int i = 0; i < 120; ++i) {
    EXPECT_EQ(r.stimuli[i].sample, 40 + 40 * i);
    EXPECT_EQ(r.stimuli[i].code, i % 6 + 1);
    EXPECT_EQ(r.stimuli[i].target, i % 6 == 2);
  }
}

// The recording PC's clock of the streams was reset halfway (a restart): the stamps jump from
// about 501000 to about 100. The clock offsets say so; every marker lands on its sample.
TEST(Xdf, AClockResetIsReanchoredAndEveryMarkerLandsOnItsSample) {
  const auto path = test::freshTempPath("xdf", "clock_reset.xdf");
  const test::XdfNumericStream eeg = eegStream(256 * 60);
  const double rate = eeg.rate;
  const std::int64_t reset = 256 * 30;
  // The recorder's clock: 1000 s at the first sample. The streams' clock reads 500000 s more
  // before the reset and 900 s less after it.
  auto recorder = [&](double sample) { return 1000.0 + sample / rate; };
  auto stream = [&](double r_time) {
    return r_time < recorder(static_cast<double>(reset)) - 0.5 / rate ? r_time + 500000.0
                                                                      : r_time - 900.0;
  };
  test::XdfExtras extras;
  for (size_t s = 0; s < eeg.samples.size(); ++s)
    extras.eeg_stamps.push_back(stream(recorder(static_cast<double>(s))));
  for (double t = 1002.0; t < 1060.0; t += 5.0) {
    const double value = stream(t) > 100000.0 ? -500000.0 : 900.0;
    extras.eeg_offsets.push_back({stream(t), value});
  }
  extras.marker_offsets = extras.eeg_offsets;
  std::vector<test::XdfMarker> markers;
  std::vector<std::int64_t> expected;
  for (int i = 0; i < 175; ++i) {
    const std::int64_t sample = 100 + 85 * i;
    markers.push_back({stream(recorder(static_cast<double>(sample))), "flash 1 nontarget", {}});
    expected.push_back(sample);
  }
  test::writeXdf(path, eeg, markers, extras);
  const Recording r = readRecording(path);
  ASSERT_EQ(r.samples, static_cast<std::int64_t>(eeg.samples.size()));
  ASSERT_EQ(r.stimuli.size(), 175u);
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.stimuli[i].sample, expected[i]) << i;
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("reset 1 time"), std::string::npos) << r.notes[0];
}

// 2 s without samples in the middle: annotated where it falls, never closed up; the markers
// after it stay on the samples taken at their time.
TEST(Xdf, ABreakInTheEegIsAnnotatedAndMarkersAfterItStayOnTheirSamples) {
  const auto path = test::freshTempPath("xdf", "gap.xdf");
  const test::XdfNumericStream eeg = eegStream(256 * 20);
  const double t0 = eeg.first_timestamp, dt = 1.0 / eeg.rate;
  test::XdfExtras extras;
  for (size_t s = 0; s < eeg.samples.size(); ++s)
    extras.eeg_stamps.push_back(t0 + static_cast<double>(s) * dt + (s >= 2560 ? 2.0 : 0.0));
  std::vector<test::XdfMarker> markers;
  for (int s : {1000, 2559, 2560, 3000, 5000})
    markers.push_back({extras.eeg_stamps[static_cast<size_t>(s)], "flash 2 nontarget", {}});
  markers.push_back({t0 + 2561 * dt + 1.0, "flash 3 nontarget", {}});  // inside the break
  test::writeXdf(path, eeg, markers, extras);
  const Recording r = readRecording(path);
  ASSERT_EQ(r.stimuli.size(), 6u);
  const std::vector<std::int64_t> expected{1000, 2559, 2560, 2560, 3000, 5000};
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.stimuli[i].sample, expected[i]) << i;
  ASSERT_EQ(r.annotations.size(), 1u);
  EXPECT_EQ(r.annotations[0].sample, 2560);
  EXPECT_NE(r.annotations[0].text.find("2.000 s without EEG samples"), std::string::npos)
      << r.annotations[0].text;
}

// Jittered stamps (0.5-1.5 ms, as LSL stamps a USB amplifier's chunks) with wild ones among them
// (a bit flipped: +6e8 s; a clock read wrong: -512 s and +1e8 s), markers at arbitrary times:
// every marker on its nearest sample, no break, and the wild stamps counted in a note.
TEST(Xdf, AWildStampIsAnOutlierNotedNeverABreakNorAShift) {
  const auto path = test::freshTempPath("xdf", "wild_stamp.xdf");
  const test::XdfNumericStream eeg = eegStream(256 * 60);
  const double t0 = eeg.first_timestamp, dt = 1.0 / eeg.rate;
  test::XdfExtras extras;
  std::uint64_t state = 12345;
  auto uniform = [&] {  // a small LCG: the test's own, so that it never changes under it
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  for (size_t s = 0; s < eeg.samples.size(); ++s)
    extras.eeg_stamps.push_back(t0 + static_cast<double>(s) * dt + 0.0005 + 0.001 * uniform());
  extras.eeg_stamps[100] += 6e8;
  extras.eeg_stamps[7000] -= 512.0;
  extras.eeg_stamps.back() += 1e8;
  std::vector<test::XdfMarker> markers;
  std::vector<std::int64_t> expected;
  for (int i = 0; i < 150; ++i) {
    // Anywhere within 0.4 periods of sample k's place on the stamps' line (t0 + k dt + the
    // jitter's 1 ms mean), either side.
    const std::int64_t k = 51 + 100 * i;
    markers.push_back(
        {t0 + k * dt + 0.001 + (uniform() - 0.5) * 0.8 * dt, "flash 1 nontarget", {}});
    expected.push_back(k);
  }
  test::writeXdf(path, eeg, markers, extras);
  const Recording r = readRecording(path);
  ASSERT_EQ(r.stimuli.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.stimuli[i].sample, expected[i]) << i;
  EXPECT_TRUE(r.annotations.empty()) << r.annotations.front().text;  // no break
  bool noted = false;
  for (const std::string& note : r.notes)
    noted |= note.rfind("3 EEG stamp(s) that no line through their neighbours explains", 0) == 0;
  EXPECT_TRUE(noted) << ::testing::PrintToString(r.notes);
}

// A file cut anywhere (at a chunk's end, or inside one) is never read as whole: refused, saying
// so, or (salvaging) read with the truncation noted.
TEST(Xdf, AFileCutAnywhereIsReportedAsCutShort) {
  const auto whole = test::freshTempPath("xdf", "whole_for_cuts.xdf");
  test::writeXdf(whole, eegStream(450), {{100.5, "flash 2 target"}, {101.0, "flash 1 nontarget"}});
  const std::string bytes = test::fileBytes(whole);
  EXPECT_EQ(readRecording(whole).samples, 450);
  const auto cut = test::freshTempPath("xdf", "cut_anywhere.xdf");
  ReadOptions salvage;
  salvage.salvage_truncated = true;
  int refused = 0, salvaged = 0;
  for (size_t at = 4; at < bytes.size(); at += 3) {
    std::ofstream(cut, std::ios::binary | std::ios::trunc) << bytes.substr(0, at);
    try {
      readRecording(cut);
      ADD_FAILURE() << "cut at byte " << at << " of " << bytes.size() << " read as whole";
    } catch (const RecordingError& e) {
      ++refused;
      const std::string what = e.what();
      EXPECT_TRUE(what.find("cut short") != std::string::npos ||
                  what.find("without the footer") != std::string::npos ||
                  what.find("no regular numeric stream") != std::string::npos)
          << at << ": " << what;
    }
    try {
      const Recording r = readRecording(cut, salvage);
      EXPECT_TRUE(r.truncated) << at;
      ++salvaged;
    } catch (const RecordingError&) {
    }
  }
  EXPECT_GT(refused, 100);
  EXPECT_GT(salvaged, 50);
}

TEST(Xdf, AFileCutShortIsRefusedOrSalvagedUpToItsLastWholeChunk) {
  const auto whole = test::freshTempPath("xdf", "whole.xdf");
  const test::XdfNumericStream eeg = eegStream(1000);
  test::writeXdf(whole, eeg, {});
  const std::string bytes = test::fileBytes(whole);
  const auto cut = test::freshTempPath("xdf", "cut.xdf");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  try {
    readRecording(cut);
    FAIL() << "a file cut short was read as whole";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("cut short"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--salvage"), std::string::npos) << e.what();
  }
  ReadOptions salvage;
  salvage.salvage_truncated = true;
  const Recording r = readRecording(cut, salvage);
  EXPECT_TRUE(r.truncated);
  ASSERT_GT(r.samples, 100);
  ASSERT_LT(r.samples, 1000);
  EXPECT_EQ(r.samples % 100, 0);  // whole chunks of 100 samples
  for (int s = 0; s < r.samples; ++s) ASSERT_EQ(r.at(2, s), eeg.samples[s][2]);
}

// libxdf trusts what a file says; ARBCI checks the chunks first, so a damaged file is refused
// with a message (or read) and never crashes the program.
TEST(Xdf, DamagedFilesAreRefusedOrReadNeverACrash) {
  const auto whole = test::freshTempPath("xdf", "undamaged.xdf");
  test::writeXdf(whole, eegStream(300), {{100.5, "flash 2 target"}});
  const std::string bytes = test::fileBytes(whole);
  const auto damaged = test::freshTempPath("xdf", "damaged.xdf");
  std::uint32_t state = 12345;
  int refused = 0, read = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string copy = bytes;
    state = state * 1664525u + 1013904223u;
    // Most damage in the headers, where the layout is declared.
    const size_t where =
        (state >> 8) % (trial % 2 ? copy.size() : std::min<size_t>(copy.size(), 1200));
    copy[where] = static_cast<char>(state >> 24);
    std::ofstream(damaged, std::ios::binary | std::ios::trunc) << copy;
    try {
      readRecording(damaged);
      ++read;
    } catch (const RecordingError&) {
      ++refused;
    }
  }
  EXPECT_EQ(refused + read, 300);
  EXPECT_GT(refused, 10);
}

}  // namespace
}  // namespace arbci::bci
