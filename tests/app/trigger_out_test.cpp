// Triggers out to the amplifier (eeg.trigger_out "serial") through the real executable, on a
// pseudo-terminal the test opens (openpty) in place of a trigger box's serial port: every flash's
// code arrives in order, none lost or doubled, each a pulse (the code, then 0 on the next frame);
// the log's write stamps lie within one frame of the flashes' swap stamps; the bytes are the
// recording's codes. A port that is not there, or is no serial port, fails before the run.
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "arbci/bci/recording.h"
#include "support/run_process.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

// A pseudo-terminal: its slave's path for arbci, its master read here into `bytes` until
// stopped.
class PseudoTerminal {
 public:
  PseudoTerminal() {
    char name[256] = {};
    if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) return;
    path_ = name;
    reader_ = std::thread([this] {
      while (!stop_) {
        pollfd p{master_, POLLIN, 0};
        if (::poll(&p, 1, 20) <= 0) continue;
        std::uint8_t buffer[256];
        const ssize_t n = ::read(master_, buffer, sizeof buffer);
        if (n <= 0) continue;
        std::lock_guard lock(mutex_);
        bytes_.insert(bytes_.end(), buffer, buffer + n);
      }
    });
  }
  ~PseudoTerminal() {
    stop_ = true;
    if (reader_.joinable()) reader_.join();
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
  }
  const std::string& path() const { return path_; }
  std::vector<std::uint8_t> bytes() {
    std::lock_guard lock(mutex_);
    return bytes_;
  }

 private:
  int master_ = -1, slave_ = -1;
  std::string path_;
  std::thread reader_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::vector<std::uint8_t> bytes_;
};

std::vector<nlohmann::json> logEvents(const std::filesystem::path& log, const std::string& event) {
  std::vector<nlohmann::json> out;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("event", "") == event) out.push_back(j);
  }
  return out;
}

TEST(TriggerOut, EveryFlashsCodeArrivesInOrderWithinAFrameOfItsSwap) {
  PseudoTerminal port;
  if (port.path().empty()) GTEST_SKIP() << "this machine gives no pseudo-terminal (openpty failed)";
  const auto folder = freshTempPath("trigger_out", "pty");
  const std::string session = folder.string() + ".json";
  std::ofstream(session) << nlohmann::json{{"eeg",
                                            {{"photodiode_channel", "Photodiode"},
                                             {"trigger_out", "serial"},
                                             {"trigger",
                                              {{"device", port.path()}, {"baud", 115200}}}}}}
                                .dump();
  const ProcessResult r = runProcess(kArbci,
                                     {"timing-check", "--headless", "--session", session,
                                      "--seconds", "8", "--out", folder.string()},
                                     120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the last bytes, read

  // The recording's flashes, in order: the codes the port must have carried.
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  std::vector<std::uint8_t> recorded;
  for (const bci::StimulusEvent& s : recording.stimuli)
    recorded.push_back(static_cast<std::uint8_t>(s.code));
  ASSERT_GE(recorded.size(), 10u);

  // Each flash a pulse: its code, then 0 (on the next frame), nothing else between.
  const std::vector<std::uint8_t> bytes = port.bytes();
  std::vector<std::uint8_t> codes;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] == 0) continue;
    codes.push_back(bytes[i]);
    EXPECT_TRUE(i + 1 == bytes.size() || bytes[i + 1] == 0) << "no reset after byte " << i;
  }
  EXPECT_EQ(codes, recorded);

  // The log: one write per byte, each stamped within one frame after its flash's swap.
  const std::vector<nlohmann::json> writes = logEvents(folder / "log.jsonl", "trigger");
  // (A run that ends on a flash's frame resets the lines as the port closes, unlogged.)
  ASSERT_TRUE(bytes.size() == writes.size() || bytes.size() == writes.size() + 1)
      << bytes.size() << " bytes, " << writes.size() << " writes";
  const double frame_s = 1.0 / 60.0;
  size_t flash = 0;
  for (const nlohmann::json& w : writes) {
    const double after = w["written_s"].get<double>() - w["swap_s"].get<double>();
    EXPECT_GE(after, 0.0) << w;
    EXPECT_LE(after, frame_s) << w;
    if (w["byte"].get<int>() == 0) continue;
    ASSERT_LT(flash, recording.stimuli.size());
    // The swap it follows is the flash's onset, as the recording stamps it.
    const double onset_s = static_cast<double>(recording.stimuli[flash].sample) / 256.0;
    EXPECT_NEAR(w["swap_s"].get<double>(), onset_s, 1.0 / 256.0) << w;
    ++flash;
  }
  const nlohmann::json summary = readJson(folder / "summary.json");
  EXPECT_EQ(summary["trigger"]["written"], writes.size()) << summary["trigger"];
  EXPECT_EQ(summary["trigger"]["failed"], 0) << summary["trigger"];
  std::filesystem::remove_all(folder);
}

TEST(TriggerOut, APortThatIsNotThereOrIsNoSerialPortFailsBeforeTheRun) {
  const auto folder = freshTempPath("trigger_out", "missing");
  const std::string session = folder.string() + ".json";
  for (const std::string device : {"/dev/ttyUSB-arbci-missing", "/dev/null"}) {
    std::ofstream(session)
        << nlohmann::json{{"eeg", {{"trigger_out", "serial"}, {"trigger", {{"device", device}}}}}}
               .dump();
    const ProcessResult r = runProcess(
        kArbci, {"run", "--headless", "--session", session, "--out", folder.string()}, 120.0);
    EXPECT_NE(r.exit_code, 0) << r.out;
    EXPECT_NE(r.err.find("eeg.trigger.device = \"" + device + "\""), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(device == "/dev/null" ? "is not a serial port" : "plugged in"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(folder / "recording.bdf"));
    std::filesystem::remove_all(folder);
  }
  // Serial without a device is refused by the settings themselves.
  std::ofstream(session) << R"({"eeg": {"trigger_out": "serial"}})";
  const ProcessResult r = runProcess(
      kArbci, {"run", "--headless", "--session", session, "--out", folder.string()}, 120.0);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("trigger.device"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
