// A headless session whose EEG comes over LSL from `arbci eeg stream` (a second process playing
// a real recording as a stand-in amplifier; machine scope, loopback only).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <thread>

#include "arbci/bci/lsl/inlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/bci/recording.h"
#include "support/background_process.h"
#include "support/test_files.h"

namespace arbci {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::string kEeg3 =
    std::string(ARBCI_SHARED_DATA_DIR) + "/eeg/bci2000_samplefiles/eeg3_1.dat";

bci::lsl::LslConfig machine() {
  bci::lsl::LslConfig c;
  c.resolve_scope = "machine";
  return c;
}

TEST(LslSession, TheRecordingHoldsTheStreamedSamplesAndItsMarkersFallOnTheFlashSamples) {
  const auto folder = test::freshTempPath("lsl_session", "recording");
  std::filesystem::create_directories(folder);
  const std::string name = "eeg3-" + std::to_string(::getpid());
  const bci::Recording file = bci::readRecording(kEeg3);
  nlohmann::json session = {
      {"description", "EEG from LSL (arbci eeg stream)"},
      {"eeg",
       {{"source", "lsl"},
        {"rate_hz", file.info.rate_hz},
        {"photodiode_channel", ""},
        {"lsl", {{"name", name}, {"type", "EEG"}, {"resolve_timeout_s", 10}}}}},
      {"lsl", {{"scope", "machine"}, {"markers", true}, {"marker_stream", name + "-session"}}}};
  const auto session_file = folder / "lsl.json";
  std::ofstream(session_file) << session.dump(2);

  // The amplifier's app states the impedances it measured in the stream's metadata.
  test::BackgroundProcess streamer(
      kArbci, {"eeg", "stream", kEeg3, "--name", name, "--wait", "--scope", "machine",
               "--impedance", "4,5,6,7,8,9,10,31"});
  const auto out = folder / "session";
  test::BackgroundProcess run(
      kArbci, {"run", "--headless", "--session", session_file.string(), "--out", out.string()});
  const auto streaming = streamer.waitForLine("streaming t0=", 30.0);
  ASSERT_TRUE(streaming) << "the session never connected";
  // The LSL time of the file's first sample, which is the recording's first.
  const double t0 = std::stod(streaming->substr(streaming->find('=') + 1));
  // The session's own Markers stream, as LabRecorder would take it.
  const auto found = bci::lsl::resolveStreams(
      machine(), bci::lsl::buildQuery("default", name + "-session", "Markers"), 10.0);
  ASSERT_EQ(found.size(), 1u) << "the session published no Markers stream";
  bci::lsl::Inlet markers(found[0], machine());
  std::this_thread::sleep_for(std::chrono::seconds(12));
  run.signal(SIGTERM);  // ends the session as Ctrl+C does
  const auto status = run.wait(30.0);
  ASSERT_TRUE(status) << "the session did not end";

  const bci::Recording recorded = bci::readRecording(out / "recording.bdf");
  ASSERT_EQ(recorded.info.channels, file.info.channels);
  EXPECT_DOUBLE_EQ(recorded.info.rate_hz, file.info.rate_hz);
  ASSERT_GT(recorded.samples, static_cast<std::int64_t>(8 * file.info.rate_hz));
  // Sample for sample the file's, from its first (the stream waited for the session), within the
  // BDF's 24-bit resolution.
  double worst = 0;
  for (int c = 0; c < file.info.channelCount(); ++c)
    for (std::int64_t s = 0; s < recorded.samples; ++s)
      worst = std::max(worst, static_cast<double>(std::abs(recorded.at(c, s) - file.at(c, s))));
  EXPECT_LT(worst, 0.05) << "microvolts";
  EXPECT_FALSE(recorded.stimuli.empty());
  // Every flash after the markers inlet connected is on the Markers stream, stamped with its
  // presentation time; that time, on the amplifier's clock, is the flash's sample in the file.
  std::vector<bci::lsl::Sample> received;
  markers.pull(received);
  std::vector<std::pair<double, std::string>> flashes;
  for (const auto& m : received)
    if (m.strings[0].rfind("flash ", 0) == 0) flashes.emplace_back(m.timestamp, m.strings[0]);
  ASSERT_GT(flashes.size(), 20u);
  int matched = 0, considered = 0;
  double worst_samples = 0;
  for (const auto& stimulus : recorded.stimuli) {
    const double at = t0 + stimulus.sample / file.info.rate_hz;
    if (at < flashes.front().first - 1e-3) continue;  // before the inlet connected
    ++considered;
    const std::string code = "flash " + std::to_string(stimulus.code) + " ";
    for (const auto& [stamp, text] : flashes) {
      if (text.rfind(code, 0) != 0) continue;
      const double off = (stamp - t0) * file.info.rate_hz - static_cast<double>(stimulus.sample);
      if (std::abs(off) <= 1.0) {
        ++matched;
        worst_samples = std::max(worst_samples, std::abs(off));
        break;
      }
    }
  }
  EXPECT_GT(considered, 20);
  EXPECT_EQ(matched, considered) << "flashes whose marker time is not their recorded sample";
  std::printf("[ measured ] %d flashes: marker time vs recorded sample within %.2f samples\n",
              considered, worst_samples);
  const nlohmann::json summary = test::readJson(out / "summary.json");
  EXPECT_EQ(summary["timing"]["lost_samples"], 0);
  // The impedances the stream's metadata gave, per channel, for the EEG panel and the record.
  const bci::Recording channels = bci::readRecording(kEeg3);
  EXPECT_EQ(summary["eeg"]["impedance"].get<std::string>().rfind(
                channels.info.channels[0] + " 4, " + channels.info.channels[1] + " 5, ", 0),
            0u)
      << summary["eeg"];
  // The stream's stamps are exact: the clock model sees no arrival jitter and no drift.
  EXPECT_LT(summary["timing"]["clock_jitter_ms"].get<double>(), 0.5);
  EXPECT_LT(std::abs(summary["timing"]["clock_drift_ppm"].get<double>()), 20.0);
}

std::vector<nlohmann::json> readLog(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

// The amplifier's LSL app dies mid-session and is started again: the session shows the fault,
// waits (no flashing decides on missing EEG), counts the gap, and goes on when the stream is back.
TEST(LslSession, AStreamLostMidSessionPausesItAndItGoesOnWhenTheStreamIsBack) {
  const auto folder = test::freshTempPath("lsl_session", "restart");
  std::filesystem::create_directories(folder);
  const std::string name = "eeg3r-" + std::to_string(::getpid());
  nlohmann::json session = {
      {"description", "EEG from LSL, the stream restarted"},
      {"eeg",
       {{"source", "lsl"},
        {"rate_hz", 256},
        {"photodiode_channel", ""},
        {"lsl", {{"name", name}, {"type", "EEG"}, {"resolve_timeout_s", 10}}}}},
      {"lsl", {{"scope", "machine"}}}};
  const auto session_file = folder / "lsl.json";
  std::ofstream(session_file) << session.dump(2);
  const std::vector<std::string> stream_args{"eeg", "stream",  kEeg3,    "--name",
                                             name,  "--scope", "machine"};
  auto first = std::make_unique<test::BackgroundProcess>(kArbci, stream_args);
  const auto out = folder / "session";
  test::BackgroundProcess run(
      kArbci, {"run", "--headless", "--session", session_file.string(), "--out", out.string()});
  std::this_thread::sleep_for(std::chrono::seconds(7));
  first->kill();  // the amplifier's app dies
  std::this_thread::sleep_for(std::chrono::seconds(2));
  test::BackgroundProcess second(kArbci, stream_args);  // and is started again
  std::this_thread::sleep_for(std::chrono::seconds(7));
  run.signal(SIGTERM);
  ASSERT_TRUE(run.wait(30.0)) << "the session did not end";

  bool fault = false, paused = false, back = false, resumed = false;
  for (const auto& line : readLog(out / "log.jsonl")) {
    if (line["event"] == "eeg_source") {
      if (line["state"] == "fault") fault = true;
      if (line["state"] == "delivering" && fault) back = true;
    }
    paused |= line["event"] == "paused" && line["reason"] == "EEG source fault";
    resumed |= line["event"] == "resumed" && paused;
  }
  EXPECT_TRUE(fault);
  EXPECT_TRUE(back);
  EXPECT_TRUE(paused) << "the paradigm went on flashing without EEG";
  EXPECT_TRUE(resumed);
  const nlohmann::json summary = test::readJson(out / "summary.json");
  // About 2 s away: the gap, counted from the timestamps either side.
  const auto lost = summary["eeg"]["lost_samples"].get<std::int64_t>();
  EXPECT_GT(lost, 256);
  EXPECT_LT(lost, 256 * 6);
  const bci::Recording recorded = bci::readRecording(out / "recording.bdf");
  bool annotated = false;
  for (const auto& a : recorded.annotations) annotated |= a.text.rfind("Lost ", 0) == 0;
  EXPECT_TRUE(annotated);
  std::printf("[ measured ] %lld samples lost while the stream was away; %lld epochs discarded\n",
              static_cast<long long>(lost),
              static_cast<long long>(summary["eeg"]["discarded_epochs"].get<std::int64_t>()));
}

}  // namespace
}  // namespace arbci
