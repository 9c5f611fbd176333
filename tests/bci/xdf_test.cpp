// XDF recordings (LabRecorder's format) read through libxdf, from files our own test writer
// makes: every sample and event is known.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

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
                  {t0 + 200.4 * dt, "flash 4 nontarget"},  // between samples: the next one
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
  EXPECT_EQ(r.stimuli[1].sample, 201);
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

std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Xdf, AFileCutShortIsRefusedOrSalvagedUpToItsLastWholeChunk) {
  const auto whole = test::freshTempPath("xdf", "whole.xdf");
  const test::XdfNumericStream eeg = eegStream(1000);
  test::writeXdf(whole, eeg, {});
  const std::string bytes = fileBytes(whole);
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
  const std::string bytes = fileBytes(whole);
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
