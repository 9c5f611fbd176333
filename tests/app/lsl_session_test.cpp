// A headless session whose EEG comes over LSL from `arbci eeg stream` (a second process playing
// a real recording as a stand-in amplifier; machine scope, loopback only).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <thread>

#include "arbci/bci/recording.h"
#include "support/background_process.h"
#include "support/test_files.h"

namespace arbci {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::string kEeg3 = std::string(ARBCI_SHARED_DATA_DIR) + "/eeg/bci2000_samplefiles/eeg3_1.dat";

TEST(LslSession, TheRecordingHoldsTheStreamedFilesSamplesUnchanged) {
  const auto folder = test::freshTempPath("lsl_session", "recording");
  std::filesystem::create_directories(folder);
  const std::string name = "eeg3-" + std::to_string(::getpid());
  const bci::Recording file = bci::readRecording(kEeg3);
  nlohmann::json session = {
      {"description", "EEG from LSL (arbci eeg stream)"},
      {"eeg", {{"source", "lsl"}, {"rate_hz", file.info.rate_hz}, {"photodiode_channel", ""},
               {"lsl", {{"name", name}, {"type", "EEG"}, {"resolve_timeout_s", 10}}}}},
      {"lsl", {{"scope", "machine"}}}};
  const auto session_file = folder / "lsl.json";
  std::ofstream(session_file) << session.dump(2);

  test::BackgroundProcess streamer(kArbci, {"eeg", "stream", kEeg3, "--name", name, "--wait",
                                            "--scope", "machine"});
  const auto out = folder / "session";
  test::BackgroundProcess run(kArbci, {"run", "--headless", "--session", session_file.string(),
                                       "--out", out.string()});
  ASSERT_TRUE(streamer.waitForLine("streaming t0=", 30.0)) << "the session never connected";
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
  const nlohmann::json summary = test::readJson(out / "summary.json");
  EXPECT_EQ(summary["timing"]["lost_samples"], 0);
}

}  // namespace
}  // namespace arbci
