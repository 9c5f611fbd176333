// The BCI2000 sample files read right: shapes, stimuli and targets from the state vector, and
// microvolts as (raw - offset) * gain, checked against an independent decoding of the raw bytes
// and against BioSig.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "arbci/bci/recording.h"
#include "support/shared_data.h"

namespace arbci::bci {
namespace {

std::string sampleFile(const std::string& name) {
  return test::sharedData("eeg/bci2000_samplefiles/" + name);
}

// The raw int16 of (sample, channel), read straight from the file's bytes.
int rawSample(const std::string& path, int sample, int channel) {
  std::ifstream in(path, std::ios::binary);
  std::string first;
  std::getline(in, first);
  std::istringstream fields(first);
  std::map<std::string, int> values;
  std::string key;
  int value = 0;
  while (fields >> key >> value) values[key] = value;
  const int record = values["SourceCh="] * 2 + values["StatevectorLen="];
  in.seekg(values["HeaderLen="] + static_cast<std::int64_t>(sample) * record + channel * 2);
  std::int16_t raw = 0;
  in.read(reinterpret_cast<char*>(&raw), 2);
  return raw;
}

// The (row, column) target pairs, one per character (180 flashes each).
std::vector<std::pair<int, int>> targetsPerCharacter(const Recording& r) {
  std::vector<std::pair<int, int>> out;
  for (size_t start = 0; start < r.stimuli.size(); start += 180) {
    std::set<int> codes;
    for (size_t i = start; i < start + 180 && i < r.stimuli.size(); ++i) {
      if (r.stimuli[i].target) codes.insert(r.stimuli[i].code);
    }
    EXPECT_EQ(codes.size(), 2u);
    out.emplace_back(*codes.begin(), *codes.rbegin());
  }
  return out;
}

TEST(Bci2000Files, Eeg3_1HasTheShapeStimuliAndTargetsOfT3OF) {
  const Recording r = readRecording(sampleFile("eeg3_1.dat"));
  EXPECT_EQ(r.format, "BCI2000");
  EXPECT_EQ(r.info.channels,
            (std::vector<std::string>{"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"}));
  EXPECT_EQ(r.info.rate_hz, 256.0);
  EXPECT_EQ(r.samples, 56840);
  ASSERT_EQ(r.stimuli.size(), 720u);
  int targets = 0;
  for (const StimulusEvent& e : r.stimuli) {
    targets += e.target;
    EXPECT_GE(e.code, 1);
    EXPECT_LE(e.code, 12);
    EXPECT_EQ(e.duration_samples, 32);  // StimulusDuration 4 blocks of 8
  }
  EXPECT_EQ(targets, 120);
  const std::vector<std::pair<int, int>> expected{{4, 8}, {5, 11}, {3, 9}, {1, 12}};  // T 3 O F
  EXPECT_EQ(targetsPerCharacter(r), expected);
  // Stimulus onsets 64 samples apart within a sequence.
  EXPECT_EQ(r.stimuli[1].sample - r.stimuli[0].sample, 64);
  EXPECT_EQ(bci2000Values(r, "TextToSpell").at(0), "T3OF");
}

TEST(Bci2000Files, Eeg3_2TargetsAre6MKQuestionMark) {
  const Recording r = readRecording(sampleFile("eeg3_2.dat"));
  const std::vector<std::pair<int, int>> expected{{6, 8}, {3, 7}, {2, 11}, {6, 12}};
  EXPECT_EQ(targetsPerCharacter(r), expected);
}

TEST(Bci2000Files, MicrovoltsAreRawMinusOffsetTimesGain) {
  for (const std::string name : {"eeg3_1.dat", "eeg2_1.dat"}) {
    const std::string path = sampleFile(name);
    const Recording r = readRecording(path);
    for (int channel : {0, r.info.channelCount() - 1}) {
      const double offset = bci2000Number(r, "SourceChOffset", channel);
      const double gain = bci2000Number(r, "SourceChGain", channel);
      for (int sample : {0, 1, 1000, static_cast<int>(r.samples) - 1}) {
        const double expected = (rawSample(path, sample, channel) - offset) * gain;
        EXPECT_NEAR(r.at(channel, sample), expected, 1e-4 * std::max(1.0, std::abs(expected)))
            << name << " ch " << channel;
      }
    }
  }
}

TEST(Bci2000Files, Eeg2_1HasNonZeroOffsetsAndOddballStimuli) {
  const Recording r = readRecording(sampleFile("eeg2_1.dat"));
  EXPECT_EQ(r.info.channelCount(), 64);
  EXPECT_EQ(r.info.rate_hz, 160.0);
  EXPECT_EQ(r.samples, 25296);
  EXPECT_NE(bci2000Number(r, "SourceChOffset", 0), 0.0);
  int targets = 0;
  for (const StimulusEvent& e : r.stimuli) {
    targets += e.target;
    EXPECT_EQ(e.target, e.code == 1);
  }
  EXPECT_EQ(r.stimuli.size(), 100u);
  EXPECT_EQ(targets, 20);
  // Offsets removed: the channel means are EEG-sized, not offset-sized.
  double mean = 0.0;
  for (std::int64_t s = 0; s < r.samples; ++s) mean += r.at(0, s);
  EXPECT_LT(std::abs(mean / r.samples), 50.0);
}

TEST(Bci2000Files, BioSigReadsTheSameSamplesOfEeg3) {
  const Recording ours = readRecording(sampleFile("eeg3_1.dat"));
  const Recording theirs = readWithBiosig(sampleFile("eeg3_1.dat"));
  ASSERT_EQ(theirs.info.channelCount(), 8);
  EXPECT_EQ(theirs.info.rate_hz, 256.0);
  ASSERT_EQ(theirs.samples, ours.samples);
  double worst = 0.0;
  for (int c = 0; c < 8; ++c) {
    for (std::int64_t s = 0; s < ours.samples; s += 7)
      worst = std::max(worst, std::abs(double(ours.at(c, s)) - theirs.at(c, s)));
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_TRUE(theirs.stimuli.empty());  // BioSig drops the states: why they are parsed here
}

TEST(Bci2000Files, SyntheticSpellerFileSpellsSPELL) {
  const Recording r = readRecording(sampleFile("P3SpellerS001R01_synthetic.dat"));
  EXPECT_EQ(r.info.channelCount(), 4);
  EXPECT_EQ(r.stimuli.size(), 120u);
  EXPECT_EQ(bci2000Values(r, "TextToSpell").at(0), "SPELL");
}

}  // namespace
}  // namespace arbci::bci
