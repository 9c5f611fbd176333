// The cycle as an instrument, through the real executable: the timing check in a window under Xvfb
// with the HMD mirror (recorded flash onsets against the photodiode's rising edges, the paradigm's
// rules met), and a check refused before it runs. The stamping itself is tested stage by stage
// (tests/session/stages: presentation, EEG acquisition with a held-up delivery), the clock model
// through stalls in tests/bci/clock_model_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include <signal.h>

#include <chrono>
#include <thread>

#include "arbci/bci/photodiode_check.h"
#include "arbci/bci/recording.h"
#include "support/background_process.h"
#include "support/run_process.h"
#include "support/test_files.h"
#include "support/xvfb_server.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

std::filesystem::path fresh(const std::string& name) {
  return freshTempPath("timing_test", name);
}

// Runs arbci with `arguments` in a window on an Xvfb display of its own (1920x1080).
ProcessResult runInWindow(std::vector<std::string> arguments, double timeout_seconds) {
  const XvfbServer x("1920x1080x24");
  arguments.insert(arguments.begin(), {"-u", "XAUTHORITY", "DISPLAY=" + x.display(), kArbci});
  return runProcess("/usr/bin/env", arguments, timeout_seconds);
}

void expectOnTarget(const std::filesystem::path& folder) {
  const nlohmann::json t = readJson(folder / "timing.json");
  const double sample_ms = 1000.0 / 256.0;
  EXPECT_LE(std::abs(t["offset_ms"]["mean"].get<double>()), 1.0) << t.dump(2);
  EXPECT_LE(t["offset_ms"]["sd"].get<double>(), sample_ms) << t.dump(2);
  // How many flashes fit in the check's seconds depends on how fast the machine presents them (on
  // late frames the schedule slips, never squeezes): ten are enough to judge the offsets, and a
  // loaded machine still shows them (18-27 in 15 s beside two busy processes, 32 on a quiet one).
  EXPECT_GE(t["flashes"].get<int>(), 10);
  EXPECT_EQ(t["count"], t["flashes"]) << t.dump(2);
  EXPECT_EQ(t["unmatched_edges"], 0) << t.dump(2);
  // The paradigm's rules, each judged and met: one stimulus at a time, a dark frame before each,
  // no SOA or dark gap under the paradigm's.
  ASSERT_EQ(t["rules"].size(), 5u) << t.dump(2);
  for (const nlohmann::json& rule : t["rules"]) EXPECT_TRUE(rule["met"].get<bool>()) << rule;
  const nlohmann::json rules = readJson(folder / "summary.json")["timing"]["flash_rules"];
  EXPECT_EQ(rules["overlapped"], 0);
  EXPECT_EQ(rules["gapless"], 0);
  // The figure is there and the session's own files beside it.
  EXPECT_GT(std::filesystem::file_size(folder / "timing.png"), 5000u);
  EXPECT_TRUE(std::filesystem::exists(folder / "recording.bdf"));
}

// The subject's view in a window of its own (the HMD mirror, full screen on monitor 0 of the
// Xvfb display) beside the experimenter's: the flashes are stamped at the HMD window's swap.
// (The simulated photodiode sees what the session says it presented; a real one on the HMD is
// what tells one swap from the other.)
// `arbci timing-check` in a window, with the HMD mirror on `monitor`, for `seconds`.
ProcessResult windowedCheckWithMirror(const std::filesystem::path& folder, int monitor,
                                      int seconds) {
  const auto session = folder.string() + ".json";
  std::ofstream(session) << R"({"hmd": {"mirror_monitor": )" << monitor << "}}";
  return runInWindow({"timing-check", "--session", session, "--seconds", std::to_string(seconds),
                      "--out", folder.string()},
                     300.0);
}

TEST(TimingCheck, InTheHmdWindowUnderXvfbOnsetsMeetThePhotodiode) {
  const auto folder = fresh("window");
  const ProcessResult r = windowedCheckWithMirror(folder, 0, 15);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  expectOnTarget(folder);
  EXPECT_EQ(readJson(folder / "timing.json")["mode"], "window");
}

TEST(TimingCheck, RefusesASessionWithoutAPhotodiodeChannel) {
  const auto folder = fresh("nodiode");
  const auto session = folder.string() + ".json";
  std::ofstream(session) << R"({"eeg": {"photodiode_channel": ""}})";
  const ProcessResult r = runProcess(
      kArbci, {"timing-check", "--headless", "--session", session, "--out", folder.string()}, 60.0);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(folder));  // refused before anything ran
  EXPECT_NE(r.err.find("eeg.photodiode_channel"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
