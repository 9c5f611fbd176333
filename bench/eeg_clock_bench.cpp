// eeg_clock_bench: the EEG clock of real-time sessions as a lab PC treats them (run it alone and
// under load: bench/under-load runs both).
//   1. stalls: `arbci run --headless --realtime` (a still head, the simulated subject and its
//      virtual photodiode) paused for 2 s by SIGSTOP while flashing, ended 14 s later; every flash
//      onset after the pause against its photodiode edge, the drift the session reports (truth:
//      0 ppm), the stalls its summary counts;
//   2. pre-flight: the default real-time session started N times, and a session reading a
//      recording streamed over LSL (`arbci eeg stream`) M times; the EEG rate each pre-flight
//      measured (truth: the source's) and whether it passed.
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "arbci/bci/photodiode_check.h"
#include "arbci/bci/recording.h"
#include "support/background_process.h"

namespace {

using namespace arbci;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

std::uintmax_t sizeOf(const fs::path& file) {
  std::error_code error;
  const auto size = fs::file_size(file, error);
  return error ? 0 : size;
}

std::optional<nlohmann::json> logEvent(const fs::path& log, const std::string& name) {
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    const auto event = nlohmann::json::parse(line, nullptr, false);
    if (!event.is_discarded() && event.value("event", "") == name) return event;
  }
  return std::nullopt;
}

struct StallRun {
  int onsets_early = 0, off_early = 0;  // within 5 s after the pause
  int onsets_late = 0, off_late = 0;    // from 5 s after it on
  int worst_late = 0;                   // samples
  double drift_ppm = 0.0, drift_uncertainty_ppm = 0.0;
  bool drift_reliable = false;
  int stalls = 0;
  double preflight_hz = 0.0;
};

std::optional<StallRun> stallRun(const std::string& arbci, const fs::path& folder) {
  fs::remove_all(folder);
  const std::string session = folder.string() + ".json";
  std::ofstream(session) << R"({"cameras": {"head_motion_m": 0.0, "head_motion_deg": 0.0},
    "paradigm": {"calibration_selections": 6, "calibration_sequences": 4, "cue_s": 0.5,
                 "pause_s": 0.5}})";
  test::BackgroundProcess run(
      arbci, {"run", "--headless", "--realtime", "--session", session, "--out", folder.string()});
  for (int i = 0; i < 600 && sizeOf(folder / "recording.bdf") < 60000; ++i)
    std::this_thread::sleep_for(100ms);
  run.signal(SIGSTOP);
  std::this_thread::sleep_for(2s);
  run.signal(SIGCONT);
  std::this_thread::sleep_for(14s);
  run.signal(SIGTERM);
  if (!run.wait(120.0)) return std::nullopt;
  StallRun out;
  std::ifstream summary_file(folder / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  const nlohmann::json& timing = summary["timing"];
  out.drift_ppm = timing["clock_drift_ppm"];
  out.drift_uncertainty_ppm = timing["clock_drift_uncertainty_ppm"];
  out.drift_reliable = timing["clock_drift_reliable"];
  out.stalls = timing["eeg_stalls"]["count"];
  if (const auto preflight = logEvent(folder / "log.jsonl", "preflight"))
    out.preflight_hz = preflight->value("eeg_rate_hz", 0.0);
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  std::int64_t stall = -1;
  for (const auto& a : recording.annotations)
    if (stall < 0 && a.text.rfind("EEG delivery stalled", 0) == 0) stall = a.sample;
  if (stall < 0) return out;
  const bci::PhotodiodeReport paired = bci::checkPhotodiode(recording, "Photodiode", 0.5);
  const double rate = recording.info.rate_hz;
  auto count = [&](std::int64_t onset, int samples_off) {
    if (onset < stall) return;
    const bool off = samples_off > 1;
    if (onset < stall + static_cast<std::int64_t>(7 * rate)) {  // 2 s paused + 5 s
      ++out.onsets_early;
      out.off_early += off;
    } else {
      ++out.onsets_late;
      out.off_late += off;
      out.worst_late = std::max(out.worst_late, samples_off);
    }
  };
  for (size_t i = 0; i < paired.paired_onsets.size(); ++i)
    count(paired.paired_onsets[i],
          static_cast<int>(std::lround(std::abs(paired.offsets_ms[i]) * rate / 1000.0)));
  for (const std::int64_t onset : paired.unmatched_onsets) count(onset, 1 << 20);
  return out;
}

// The session started `starts` times in real time (`session_for(folder)` names its session file,
// empty for the default, and may start what it needs); the EEG rate each pre-flight measured.
// Prints a table row; true when every start passed.
bool preflightStarts(const std::string& arbci, const fs::path& scratch, int starts,
                     const std::string& what,
                     const std::function<std::string(const fs::path&)>& session_for) {
  std::vector<double> rates;
  int refused = 0, unfinished = 0;
  for (int i = 0; i < starts; ++i) {
    const fs::path folder = scratch / ("start" + std::to_string(i));
    std::vector<std::string> args = {"run", "--headless", "--realtime", "--out", folder.string()};
    if (const std::string session = session_for(folder); !session.empty()) {
      args.push_back("--session");
      args.push_back(session);
    }
    test::BackgroundProcess run(arbci, args);
    std::optional<nlohmann::json> preflight;
    for (int k = 0; k < 300 && !preflight; ++k) {
      std::this_thread::sleep_for(100ms);
      preflight = logEvent(folder / "log.jsonl", "preflight");
    }
    run.signal(SIGTERM);
    run.wait(30.0);
    if (!preflight) {
      ++unfinished;
    } else if (!preflight->value("passed", false)) {
      ++refused;
      std::fprintf(stderr, "start %d refused: %s\n", i, preflight->dump().c_str());
    } else {
      rates.push_back(preflight->value("eeg_rate_hz", 0.0));
    }
    fs::remove_all(folder);
  }
  std::sort(rates.begin(), rates.end());
  if (rates.empty()) {
    std::printf("| %s | %d | 0 | %d | %d | - | - | - |\n", what.c_str(), starts, refused,
                unfinished);
  } else {
    std::printf("| %s | %d | %zu | %d | %d | %.1f | %.1f | %.1f |\n", what.c_str(), starts,
                rates.size(), refused, unfinished, rates.front(), rates[rates.size() / 2],
                rates.back());
  }
  return refused == 0 && unfinished == 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"eeg_clock_bench: stamps and drift across a 2 s stall, pre-flight EEG rates"};
  std::string arbci = "build/release/arbci";
  int stall_runs = 2, starts = 50, lsl_starts = 20;
  std::string lsl_file = std::string(ARBCI_SHARED_DATA_DIR) + "/eeg/bci2000_samplefiles/eeg3_1.dat";
  app.add_option("--arbci", arbci, "the arbci executable")->capture_default_str();
  app.add_option("--stall-runs", stall_runs, "sessions paused once")->capture_default_str();
  app.add_option("--starts", starts, "real-time starts for the pre-flight (simulated subject)")
      ->capture_default_str();
  app.add_option("--lsl-starts", lsl_starts, "real-time starts for the pre-flight (LSL source)")
      ->capture_default_str();
  app.add_option("--lsl-file", lsl_file, "the recording streamed over LSL")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const fs::path scratch =
      fs::temp_directory_path() / ("arbci-clock-bench-" + std::to_string(getpid()));
  fs::create_directories(scratch);

  std::printf("A real-time session paused 2 s (SIGSTOP) while flashing\n");
  std::printf(
      "| run | onsets 0-5 s after | > 1 sample off | onsets later | > 1 sample off | worst | "
      "stalls in the summary | drift ppm (truth 0) | +/- | reliable | pre-flight Hz |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  int failures = 0;
  for (int i = 0; i < stall_runs; ++i) {
    const auto r = stallRun(arbci, scratch / ("stall" + std::to_string(i)));
    if (!r) {
      std::printf("| %d | did not end |\n", i + 1);
      ++failures;
      continue;
    }
    std::printf("| %d | %d | %d | %d | %d | %d | %d | %+.1f | %.1f | %s | %.1f |\n", i + 1,
                r->onsets_early, r->off_early, r->onsets_late, r->off_late, r->worst_late,
                r->stalls, r->drift_ppm, r->drift_uncertainty_ppm, r->drift_reliable ? "yes" : "no",
                r->preflight_hz);
    failures +=
        r->off_late > 0 || r->stalls < 1 || (r->drift_reliable && std::abs(r->drift_ppm) > 20.0);
  }

  std::printf("\nPre-flight of real-time sessions (the EEG rate it measured)\n");
  std::printf(
      "| source | starts | passed | refused | no verdict in 30 s | rate min | median | max |\n"
      "|---|---|---|---|---|---|---|---|\n");
  const bool simulated_ok = preflightStarts(arbci, scratch, starts, "simulated subject, 256 Hz",
                                            [](const fs::path&) { return std::string(); });
  // A live source: `arbci eeg stream` publishes a recording over LSL (machine scope) and the
  // session reads it as it would an amplifier's outlet.
  const bci::Recording file = bci::readRecording(lsl_file);
  const std::string stream = "clock-bench-" + std::to_string(getpid());
  const nlohmann::json lsl_session = {
      {"eeg",
       {{"source", "lsl"},
        {"rate_hz", file.info.rate_hz},
        {"photodiode_channel", ""},
        {"lsl", {{"name", stream}, {"type", "EEG"}, {"resolve_timeout_s", 10}}}}},
      {"lsl", {{"scope", "machine"}}}};
  const fs::path lsl_session_file = scratch / "lsl.json";
  std::ofstream(lsl_session_file) << lsl_session.dump(2);
  char what[160];
  std::snprintf(what, sizeof what, "LSL outlet of arbci eeg stream, %.0f Hz", file.info.rate_hz);
  std::unique_ptr<test::BackgroundProcess> streamer;
  const bool lsl_ok = preflightStarts(arbci, scratch, lsl_starts, what, [&](const fs::path&) {
    // A fresh outlet for each start: `--wait` streams from the first consumer on, once.
    streamer = std::make_unique<test::BackgroundProcess>(
        arbci, std::vector<std::string>{"eeg", "stream", lsl_file, "--name", stream, "--wait",
                                        "--scope", "machine"});
    return lsl_session_file.string();
  });
  streamer.reset();
  fs::remove_all(scratch);
  return failures == 0 && simulated_ok && lsl_ok ? 0 : 1;
}
