// EEG through eegdev's `datafile` device, which plays a BDF file as if it were an amplifier, in
// real time: the source as a session opens it, and its refusals.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/eegdev_source.h"
#include "arbci/bci/recording.h"
#include "arbci/session/eeg_sources.h"
#include "arbci/session/stages/eeg_acquisition_stage.h"
#include "arbci/session/stages/recording_stage.h"
#include "support/stage_bench.h"
#include "support/test_files.h"

namespace arbci {
namespace {

const std::string kEeg3 =
    std::string(ARBCI_SHARED_DATA_DIR) + "/eeg/bci2000_samplefiles/eeg3_1.dat";
constexpr double kRangeUv = 8000.0;

std::string field(const std::string& text, size_t width) {
  std::string f = text.substr(0, width);
  f.resize(width, ' ');
  return f;
}

// A BDF as BioSemi's ActiView writes it: 1-second records, 24-bit samples, a Status channel
// last (the layout eegdev's datafile device reads; it cannot read BDF+ annotation channels).
void writeBiosemiBdf(const bci::Recording& r, const std::filesystem::path& path) {
  const int rate = static_cast<int>(r.info.rate_hz);
  const int channels = r.info.channelCount() + 1;
  const std::int64_t records = r.samples / rate;
  std::string h =
      "\xff"
      "BIOSEMI" +
      field("X", 80) + field("eeg3_1 for eegdev", 80) +
      "01.01.26"
      "00.00.00" +
      field(std::to_string(256 * (channels + 1)), 8) + field("24BIT", 44) +
      field(std::to_string(records), 8) + field("1", 8) + field(std::to_string(channels), 4);
  const auto each = [&](auto value, size_t width) {
    for (int c = 0; c < channels; ++c) h += field(value(c), width);
  };
  const int eeg = r.info.channelCount();
  each([&](int c) { return c < eeg ? r.info.channels[c] : std::string("Status"); }, 16);
  each([&](int c) { return std::string(c < eeg ? "Active Electrode" : "Triggers and Status"); },
       80);
  each([&](int c) { return std::string(c < eeg ? "uV" : "Boolean"); }, 8);
  each([&](int c) { return c < eeg ? std::string("-8000") : std::string("-8388608"); }, 8);
  each([&](int c) { return c < eeg ? std::string("8000") : std::string("8388607"); }, 8);
  each([&](int) { return std::string("-8388608"); }, 8);
  each([&](int) { return std::string("8388607"); }, 8);
  each([&](int) { return std::string(""); }, 80);
  each([&](int) { return std::to_string(rate); }, 8);
  each([&](int) { return std::string(""); }, 32);
  std::ofstream out(path, std::ios::binary);
  out << h;
  for (std::int64_t record = 0; record < records; ++record)
    for (int c = 0; c < channels; ++c)
      for (int s = 0; s < rate; ++s) {
        std::int32_t digital = 0;
        if (c < eeg) {
          const double uv = r.at(c, record * rate + s);
          digital = static_cast<std::int32_t>(
              std::lround((uv + kRangeUv) / (2 * kRangeUv) * 16777215.0 - 8388608.0));
        }
        const char bytes[3] = {static_cast<char>(digital & 0xff),
                               static_cast<char>((digital >> 8) & 0xff),
                               static_cast<char>((digital >> 16) & 0xff)};
        out.write(bytes, 3);
      }
}

// The eegdev source as the session opens it (eeg.source "eegdev", its device string), acquired
// in real time by the acquisition stage and written by the recording stage: the file's samples
// arrive unchanged.
TEST(EegdevSession, TheDatafileDeviceDeliversTheBdfIntoTheRecordingUnchanged) {
  const auto folder = test::freshTempPath("eegdev_session", "datafile");
  std::filesystem::create_directories(folder);
  const bci::Recording source = bci::readRecording(kEeg3);
  const auto bdf = folder / "eeg3_biosemi.bdf";
  writeBiosemiBdf(source, bdf);
  const bci::Recording file = bci::readRecording(bdf);  // what the file holds, quantised
  ASSERT_EQ(file.info.channels, source.info.channels);  // the reader keeps Status as events

  const nlohmann::json settings = {{"eeg",
                                    {{"source", "eegdev"},
                                     {"rate_hz", source.info.rate_hz},
                                     {"photodiode_channel", ""},
                                     {"eegdev", {{"device", "datafile|path|" + bdf.string()}}}}}};
  const session::SessionConfig config = session::SessionConfig::parse(settings, "eegdev.json");
  test::StageBench bench("eegdev", session::Clock::Mode::RealTime);
  session::EegAcquisitionStage eeg(
      {config.eeg, 0.06, "eegdev.json"},
      session::openEegSource(config.eeg, {}, bench.clock(), "eegdev.json"), bench.clock(),
      bench.services());
  const auto path = folder / "recording.bdf";
  session::RecordingStage recording({path, eeg.info(), {}}, bench.services());
  // Four seconds of the file, played in real time, a cycle every 16 ms.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(4);
  while (std::chrono::steady_clock::now() < until) {
    bench.record.time_s = bench.clock().frameTime(bench.record.frame);
    bench.step(eeg);
    bench.step(recording);
    EXPECT_EQ(bench.record.eeg.fault, "");
    bench.next();
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
  }
  session::Cycle end = bench.cycle();
  eeg.stop(end, "done");
  recording.stop(end, "done");

  const bci::Recording recorded = bci::readRecording(path);
  // The EEG channels (the Status channel is a trigger, not EEG), sample for sample from the
  // file's first, within the two files' 24-bit steps.
  ASSERT_EQ(recorded.info.channels, source.info.channels);
  ASSERT_GT(recorded.samples, static_cast<std::int64_t>(2 * source.info.rate_hz));
  double worst = 0;
  for (int c = 0; c < recorded.info.channelCount(); ++c)
    for (std::int64_t s = 0; s < recorded.samples; ++s)
      worst = std::max(worst, static_cast<double>(std::abs(recorded.at(c, s) - file.at(c, s))));
  EXPECT_LT(worst, 0.005) << "microvolts";
  EXPECT_EQ(bench.previous.eeg.lost_samples, 0);
}

// `seconds` of a ramp on `labels` at 256 Hz: sample s of channel c is (c + 1) * 10 + s / 100 uV.
bci::Recording ramp(const std::vector<std::string>& labels, int seconds) {
  bci::Recording r;
  r.info.rate_hz = 256;
  r.info.channels = labels;
  r.samples = 256 * seconds;
  r.data.resize(labels.size() * static_cast<size_t>(r.samples));
  for (size_t c = 0; c < labels.size(); ++c)
    for (std::int64_t s = 0; s < r.samples; ++s)
      r.data[c * r.samples + s] = static_cast<float>((c + 1) * 10 + s / 100.0);
  return r;
}

// A file of 512 samples (34 blocks of 15 and 2 more) played to its end: all 512 arrive, the last
// block short, and the end is named as the end of the file, not as a lost connection.
TEST(EegdevSource, AFilePlayedToItsEndDeliversEverySampleAndSaysItEnded) {
  const auto folder = test::freshTempPath("eegdev_source", "end");
  std::filesystem::create_directories(folder);
  const auto bdf = folder / "short.bdf";
  writeBiosemiBdf(ramp({"Fz", "Cz", "Pz"}, 2), bdf);
  bci::EegdevSourceSettings settings;
  settings.device = "datafile|path|" + bdf.string();
  bci::EegdevSource source(settings);
  std::int64_t next = 0;
  double worst = 0;
  for (int i = 0; i < 400 && source.fault().empty(); ++i) {
    for (const bci::Block& b : source.poll()) {
      EXPECT_EQ(b.first_sample, next);
      for (int s = 0; s < b.samples; ++s)
        worst = std::max(worst, std::abs(b.at(1, s) - (20 + (b.first_sample + s) / 100.0)));
      next += b.samples;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  EXPECT_EQ(next, 512);
  EXPECT_LT(worst, 0.01) << "microvolts";
  EXPECT_NE(source.fault().find("the file ended (512 samples played)"), std::string::npos)
      << source.fault();
  EXPECT_EQ(source.poll().size(), 0u);  // nothing after the end
}

// A BDF whose labels eegdev does not take as EEG: the refusal says which labels it takes, and
// names the file's.
TEST(EegdevSource, AFileWithoutEegLabelsIsRefusedNamingTheRuleAndItsLabels) {
  const auto folder = test::freshTempPath("eegdev_source", "labels");
  std::filesystem::create_directories(folder);
  const auto bdf = folder / "numbered.bdf";
  writeBiosemiBdf(ramp({"Ch1", "Ch2"}, 1), bdf);
  bci::EegdevSourceSettings settings;
  settings.device = "datafile|path|" + bdf.string();
  try {
    bci::EegdevSource source(settings);
    FAIL() << "a file without EEG channels was accepted";
  } catch (const bci::EegdevError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("has no EEG channels"), std::string::npos) << what;
    EXPECT_NE(what.find("10-20 electrode name"), std::string::npos) << what;
    EXPECT_NE(what.find("labelled Ch1, Ch2"), std::string::npos) << what;
  }
}

TEST(EegdevSource, AnUnreadableDeviceIsRefusedWithTheReasonAndTheSyntax) {
  bci::EegdevSourceSettings settings;
  settings.device = "nosuchdevice";
  try {
    bci::EegdevSource source(settings);
    FAIL();
  } catch (const bci::EegdevError& e) {
    EXPECT_NE(std::string(e.what()).find("no installed eegdev plugin"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("datafile|path|"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arbci
