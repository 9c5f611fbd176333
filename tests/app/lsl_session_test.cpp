// A live session: its EEG comes over LSL from `arbci eeg stream` (a second process playing a real
// recording as a stand-in amplifier; machine scope, loopback only), every sample recorded and the
// Markers stream's flashes on their recorded samples. A stream lost and back is tested at its own
// levels: the source's reconnection (tests/bci/lsl_loopback_test.cpp), the EEG stage's fault and
// the paradigm's pause (tests/session/stages).
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
  const nlohmann::json summary = test::readJson(out / "summary.json");
  EXPECT_EQ(summary["timing"]["lost_samples"], 0);
  // The impedances the stream's metadata gave, per channel, for the EEG panel and the record.
  const bci::Recording channels = bci::readRecording(kEeg3);
  EXPECT_EQ(summary["eeg"]["impedance"].get<std::string>().rfind(
                channels.info.channels[0] + " 4, " + channels.info.channels[1] + " 5, ", 0),
            0u)
      << summary["eeg"];
}

}  // namespace
}  // namespace arbci
