// `arbci timing-check`: flashes only, for a while, then the recorded flash onsets against the
// photodiode's rising edges: timing.json and a histogram.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/bci/photodiode_check.h"
#include "arbci/render/window_context.h"
#include "arbci/session/session.h"
#include "commands/commands.h"
#include "eeg/timing_plot.h"
#include "hmd/headless_session.h"
#include "support/cli_error.h"
#include "support/interrupt.h"
#include "support/session_file.h"
#include "workstation/workstation.h"

namespace arbci::app {
namespace {

struct TimingCheckOptions {
  std::string session, out;
  bool headless = false;
  double seconds = 30.0;
};

nlohmann::json toJson(const bci::PhotodiodeReport& r, double target_sd_ms) {
  return {
      {"channel", r.channel},
      {"rate_hz", r.rate_hz},
      {"offset_ms", {{"mean", r.mean_ms}, {"sd", r.sd_ms}, {"min", r.min_ms}, {"max", r.max_ms}}},
      {"count", r.count},
      {"flashes", r.flashes},
      {"photodiode_edges", r.edges},
      {"unmatched_flashes", r.unmatched_flashes},
      {"unmatched_edges", r.unmatched_edges},
      {"target", {{"abs_mean_ms", 1.0}, {"sd_ms", target_sd_ms}}},
      {"within_target", std::abs(r.mean_ms) <= 1.0 && r.sd_ms <= target_sd_ms &&
                            r.count == r.flashes && r.unmatched_edges == 0}};
}

int runTimingCheck(const TimingCheckOptions& o) {
  const session::SessionConfig config = loadSessionOption(o.session);
  if (config.eeg.photodiode_channel.empty() && config.eeg.photodiode_marker.empty())
    throw CliError(config.source +
                   ": eeg.photodiode_channel and eeg.photodiode_marker are empty: the timing "
                   "check needs a photodiode channel (simulated: any name adds a virtual one) or "
                   "the marker a photodiode on a trigger input records");
  if (std::filesystem::exists(o.out) && !std::filesystem::is_empty(o.out))
    throw CliError(o.out + ": exists and is not empty; choose a new folder");
  session::SessionOptions options;
  options.folder = o.out;
  options.flashes_only_s = o.seconds;
  options.progress = &std::cerr;
  const bool headless = o.headless || !render::displayAvailable();
  try {
    if (headless) {
      auto context = render::createHeadlessContext({64, 64});
      watchInterrupts();
      runHeadlessSession(config, options, *context);
    } else {
      runWorkstation(config, options, {{}, false, true, true, {}, {}});
    }
  } catch (const std::runtime_error& error) {
    throw CliError(error.what());
  }
  const auto folder = std::filesystem::path(o.out);
  // A run that ended early (a failed pre-flight, an interrupt) has no flashes to judge.
  std::ifstream summary_file(folder / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file, nullptr, false);
  if (summary.is_discarded())
    throw CliError("the timing check did not run: " + (folder / "summary.json").string() +
                   " is missing or unreadable");
  if (summary.value("ended", "") != "finished")
    throw CliError("the timing check did not run: " +
                   summary.value("end_reason", std::string("?")));
  const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
  bci::PhotodiodeReport report;
  try {
    // A diode on a trigger input (its marker) where the session names one, else its channel.
    report = config.eeg.photodiode_marker.empty()
                 ? bci::checkPhotodiode(recording, config.eeg.photodiode_channel,
                                        0.5 * config.paradigm.soaSeconds())
                 : bci::checkPhotodiodeMarkers(recording, config.eeg.photodiode_marker,
                                               0.5 * config.paradigm.soaSeconds());
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  const double sample_ms = 1000.0 / recording.info.rate_hz;
  nlohmann::json out = toJson(report, sample_ms);
  // The paradigm's rules, from the session's own count of what it presented (summary.json).
  const nlohmann::json& timing = summary["timing"];
  const nlohmann::json& rules_seen = timing["flash_rules"];
  // Measured on the EEG samples of presented frames: within one sample (each end is stamped to
  // the next sample) and half a frame (a frame presented a little late) of the paradigm's.
  const double tolerance_ms = sample_ms + 500.0 / config.paradigm.display_hz;
  auto at_least = [&](const nlohmann::json& value, double limit) {
    return value.is_null() || value.get<double>() >= limit - tolerance_ms;
  };
  const std::vector<std::pair<std::string, bool>> rules{
      {"every flash on its photodiode edge (|mean| <= 1 ms, SD <= one sample, all paired)",
       out["within_target"].get<bool>()},
      {"no flash while another is lit (" + rules_seen["overlapped"].dump() + " overlapped)",
       rules_seen["overlapped"].get<int>() == 0},
      {"a dark frame before every flash (" + rules_seen["gapless"].dump() + " without)",
       rules_seen["gapless"].get<int>() == 0},
      {"no SOA under the paradigm's " + timing["soa_ms"]["frames"].dump() + " ms (least " +
           timing["soa_ms"]["min"].dump() + " ms)",
       at_least(timing["soa_ms"]["min"], timing["soa_ms"]["frames"].get<double>())},
      {"no dark gap under " + rules_seen["gap_ms_configured"].dump() + " ms (least " +
           rules_seen["min_gap_ms"].dump() + " ms)",
       at_least(rules_seen["min_gap_ms"], rules_seen["gap_ms_configured"].get<double>())}};
  std::string broken;
  for (const auto& [rule, met] : rules) {
    out["rules"].push_back({{"rule", rule}, {"met", met}});
    if (!met) broken += (broken.empty() ? "" : "; ") + rule;
  }
  // Where the frames were presented: a headset's runtime, or the session's own stamp / a window.
  const std::string mode = config.hmd.output == "openxr" ? "openxr"
                           : headless                    ? "headless"
                                                         : "window";
  out["mode"] = mode;
  out["seconds"] = o.seconds;
  std::ofstream(folder / "timing.json") << out.dump(2) << "\n";
  writeTimingHistogram(folder / "timing.png", report);
  std::cout << "timing check (" << mode << "): " << report.count << " of " << report.flashes
            << " flashes paired with photodiode edges (" << report.edges << " edges); offset mean "
            << report.mean_ms << " ms, SD " << report.sd_ms << " ms, min " << report.min_ms
            << " ms, max " << report.max_ms << " ms\n"
            << "target: |mean| <= 1 ms, SD <= " << sample_ms
            << " ms (one sample): " << (out["within_target"].get<bool>() ? "met" : "NOT met")
            << "\n";
  for (const auto& [rule, met] : rules)
    std::cout << (met ? "  met:     " : "  BROKEN:  ") << rule << "\n";
  std::cout << "wrote " << (folder / "timing.json").string() << " and "
            << (folder / "timing.png").string() << "\n";
  if (broken.empty()) return 0;
  std::cerr << "arbci: timing check failed: " << broken << "\n";
  return 4;
}

}  // namespace

void addTimingCheckCommand(CLI::App& root, int& exit_code) {
  auto o = std::make_shared<TimingCheckOptions>();
  CLI::App* cmd = root.add_subcommand(
      "timing-check",
      "Check the stimulus time stamps against a photodiode: runs flashes only (the calibration\n"
      "paradigm) for --seconds, with the photodiode patch in a corner of each eye's view, then\n"
      "pairs every recorded flash onset with the photodiode channel's nearest rising edge.\n"
      "Writes DIR/timing.json (offset mean, SD, min, max in ms, count) and DIR/timing.png (a\n"
      "histogram) beside the session's files. A real photodiode goes on the patch and into the\n"
      "amplifier channel named eeg.photodiode_channel (or, on a trigger input, the marker named\n"
      "eeg.photodiode_marker); the simulated subject has a virtual one.\n"
      "Exit status: 0 within the target (|mean| <= 1 ms, SD <= one sample, every flash paired)\n"
      "with the paradigm's rules kept (no flash while another is lit, a dark frame before each,\n"
      "no SOA or dark gap under the paradigm's); 4 when a rule broke (it is named); 1 on bad\n"
      "input.");
  cmd->add_option("--session", o->session, "session file (default: the embedded simulated one)");
  cmd->add_flag("--headless", o->headless, "no window (automatic when there is no display)");
  cmd->add_option("--seconds", o->seconds, "how long to flash (session seconds)")
      ->check(CLI::Range(2.0, 3600.0))
      ->capture_default_str();
  cmd->add_option("--out", o->out, "output folder (new or empty)")->required();
  cmd->callback([o, &exit_code] { exit_code = runTimingCheck(*o); });
}

}  // namespace arbci::app
