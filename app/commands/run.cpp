// `arbci run`: the workstation. Windowed with the experimenter panels and the HMD mirror, or
// headless (chosen automatically without a display) for batch work and tests.
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "arbci/core/whole_file.h"
#include "arbci/render/window_context.h"
#include "arbci/session/session.h"
#include "arbci/session/settings_schema.h"
#include "commands/bids_options.h"
#include "commands/commands.h"
#include "eeg/session_report.h"
#include "hmd/headless_session.h"
#include "support/cli_error.h"
#include "support/interrupt.h"
#include "support/schema_option.h"
#include "support/session_file.h"
#include "support/session_folder.h"
#include "workstation/start_error_window.h"
#include "workstation/workstation.h"

namespace arbci::app {
namespace {

struct RunOptions {
  std::string session, out, script;
  bool headless = false, realtime = false, start_now = false, wait_for_start = false,
       exit_when_done = false, overwrite = false;
  std::optional<int> trials;  // paradigm.trials
  std::optional<int> seed;    // eeg.seed
  double fault_wait_s = 5.0;
  std::string bids_root;  // --bids: export the session folder there when it ends
  BidsEntities bids;
  BidsParticipant participant;  // --age, --sex, --handedness: the summary's labels
};

// arbci-session-<date>-<time>, with -2, -3, ... when a session of the same second exists.
std::string defaultFolder() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof name, "arbci-session-%Y%m%d-%H%M%S", &local);
  std::string folder = name;
  for (int n = 2; std::filesystem::exists(folder); ++n)
    folder = std::string(name) + "-" + std::to_string(n);
  return folder;
}

void printSummary(const session::Session& session) {
  std::cout << "session folder: " << session.folder().string() << "\n";
  // The same lines as the Session panel's.
  if (const auto& trials = session.last().paradigm.trials) {
    for (const session::TrialRecord& t : *trials) std::cout << session::selectionLine(t) << "\n";
  }
  const session::Percentiles p = session.timing().totalPercentiles();
  std::cout << std::fixed << std::setprecision(2) << "cycle compute time: p50 " << p.p50
            << " ms, p99 " << p.p99 << " ms, max " << p.max << " ms; overruns (> "
            << session.timing().budgetMs() << " ms): " << session.timing().overruns() << "\n";
  const nlohmann::json timing = session.summary()["timing"];
  auto ms = [](const nlohmann::json& v) { return v.is_number() ? v.get<double>() : 0.0; };
  std::cout << "flashes as presented: SOA median " << ms(timing["soa_ms"]["median"])
            << " ms (configured " << ms(timing["soa_ms"]["configured"]) << "), flash median "
            << ms(timing["flash_ms"]["median"]) << " ms; late frames " << timing["late_frames"]
            << ", lost EEG samples " << timing["lost_samples"] << "\n";
  const nlohmann::json stalls = timing.value("eeg_stalls", nlohmann::json::object());
  std::cout << "EEG clock: drift " << ms(timing["clock_drift_ppm"]) << " ppm +/- "
            << ms(timing["clock_drift_uncertainty_ppm"])
            << (timing.value("clock_drift_reliable", false) ? "" : " (not reliable yet)")
            << "; stalls " << stalls.value("count", 0);
  if (stalls.value("count", 0) > 0)
    std::cout << " (longest " << ms(stalls["longest_s"]) << " s, "
              << stalls.value("uncertain_flashes", 0) << " flash stamps uncertain)";
  std::cout << "\n";
  std::cout << "ended: " << session.endKind();
  if (session.endReason() != session.endKind()) std::cout << " (" << session.endReason() << ")";
  std::cout << "\n";
  if (!std::filesystem::exists(session.folder() / "summary.json"))
    std::cout << "summary.json could not be written (a full disk?): the figures above are the "
                 "run's summary\n";
}

int runSession(const RunOptions& o);
int runSessionIn(const RunOptions& o, bool headless);

// The session's folder into the BIDS dataset, once it has ended; the folder stays as it is.
int runAndExport(const RunOptions& o) {
  const bool windowed = !o.headless && render::displayAvailable();
  if (!o.bids_root.empty()) {
    // In the window the experimenter gives the subject on the start screen.
    if (o.bids.subject.empty() && !windowed)
      throw CliError("--bids needs --subject (the BIDS subject label)");
    BidsEntities check = o.bids;
    if (check.subject.empty()) check.subject = "unnamed";
    try {
      checkBidsEntities(check);
    } catch (const BidsError& error) {
      throw CliError(error.what());
    }
  } else if (!o.bids.subject.empty() || !o.bids.session.empty() || !o.bids.run.empty()) {
    throw CliError("--subject, --bids-session and --run go with --bids ROOT");
  }
  try {
    checkBidsParticipant(o.participant);  // recorded in summary.json with or without --bids
  } catch (const BidsError& error) {
    throw CliError(error.what());
  }
  RunOptions run = o;
  if (run.out.empty()) run.out = defaultFolder();
  const int status = runSession(run);
  if (o.bids_root.empty()) return status;
  try {
    // The labels the run ended with: the command line's, or what the start screen changed.
    BidsEntities entities = o.bids;
    std::ifstream in(std::filesystem::path(run.out) / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    if (summary.is_object() && summary.contains("labels")) {
      const nlohmann::json& l = summary["labels"];
      entities = {l.value("subject", ""), l.value("session", ""), l.value("task", "arbci"),
                  l.value("run", "")};
    }
    const BidsExport done = exportToBids(run.out, o.bids_root, entities);
    reportBidsExport(done);
    // The run number is the export's choice, made after the session wrote its summary: the
    // summary names it too, and where the run went.
    if (summary.is_object()) {
      nlohmann::json updated = summary;
      updated["labels"]["run"] = done.run;
      updated["bids"] = {{"root", o.bids_root}, {"eeg_file", done.eeg_file.string()}};
      if (const std::string why = core::writeWholeFile(
              std::filesystem::path(run.out) / "summary.json", updated.dump(2) + "\n");
          !why.empty())
        std::cerr << "arbci run: summary.json not updated with the BIDS run: " << why << "\n";
    }
  } catch (const std::exception& error) {
    throw CliError(std::string("the session ended, but its BIDS export failed: ") + error.what() +
                   "; the session folder " + run.out +
                   " is intact: export it with `arbci bids export`");
  }
  return status;
}

int runSession(const RunOptions& o) {
  const bool headless = o.headless || !render::displayAvailable();
  if (!o.script.empty() && headless)
    throw CliError("--script drives the window: it needs a display (run it under xvfb-run)");
  if (headless) return runSessionIn(o, true);
  try {
    return runSessionIn(o, false);
  } catch (const CliError& error) {
    // Started from a desktop, the terminal may be nowhere: the window says it too (and the
    // terminal once it closes). A script that failed on it exits 4, as in the workstation.
    if (!showStartError(error.what(), o.script) && !o.script.empty())
      throw CliError(error.what(), 4);
    throw;
  }
}

// The folder's report.html, once the run has ended; a report that cannot be written is said and
// changes nothing else (the run's files are whole).
void writeReport(const std::filesystem::path& folder) {
  if (!std::filesystem::exists(folder / "summary.json")) return;
  try {
    std::cout << "report: " << writeSessionReport(folder).string() << "\n";
  } catch (const std::exception& error) {
    std::cerr << "arbci run: no report.html: " << error.what() << "\n";
  }
}

int runSessionIn(const RunOptions& o, bool headless) {
  const session::SessionConfig config = loadSessionOption(o.session);
  session::SessionOptions options;
  if (!o.out.empty()) claimFolder(o.out, o.overwrite);
  options.folder = o.out.empty() ? defaultFolder() : o.out;
  FolderClaim claim(options.folder);
  if (o.trials) options.trials = *o.trials;
  options.labels = {
      o.bids.subject,    o.bids.session,          o.bids.task, o.bids.run, o.participant.age,
      o.participant.sex, o.participant.handedness};
  if (o.seed) options.seed = static_cast<std::uint64_t>(*o.seed);
  options.fault_wait_s = o.fault_wait_s;
  options.progress = &std::cerr;
  try {
    if (!headless) {
      // Once open, the window shows the session's own failures and offers a retry in place.
      const int status =
          runWorkstation(config, options,
                         {o.script, !o.start_now, o.exit_when_done,
                          // Started at once and closed at the end, with no script: a batch
                          // run in a window, which nobody watches. What would wait for an
                          // experimenter (a failed pre-flight, objects out of view) ends it.
                          o.start_now && o.exit_when_done && o.script.empty(), o.bids_root,
                          [&] { claim.keep(); }});
      writeReport(options.folder);
      return status;
    }
    // A live amplifier cannot be stepped by a simulated clock: it runs on the wall clock.
    options.clock = !o.realtime && !config.eeg.live() ? session::Clock::Mode::Stepped
                                                      : session::Clock::Mode::RealTime;
    if (config.eeg.live() && !o.realtime)
      std::cerr << "eeg.source is \"" << config.eeg.source
                << "\" (a live amplifier): running in real time\n";
    auto context = render::createHeadlessContext({64, 64});
    watchInterrupts();
    OpenedSession opened = runHeadlessSession(config, options, *context, [&] { claim.keep(); });
    printSummary(*opened.session);
    writeReport(opened.session->folder());
    return opened.session->endKind() == "finished" ? 0 : 3;
  } catch (const session::SessionConfigError& error) {
    throw CliError(error.what());
  } catch (const render::GlError& error) {
    throw CliError(error.what());
  } catch (const std::runtime_error& error) {
    throw CliError(error.what());
  }
}

}  // namespace

void addRunCommand(CLI::App& root, int& exit_code) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* run = root.add_subcommand(
      "run",
      "Run a session: calibration run and training when there is no model, then online\n"
      "trials (select an object, the robot grasps it, select a cell, the robot puts it\n"
      "down). Without --session the embedded simulated world runs: simulated cameras,\n"
      "subject and arm. Writes a session folder (recording.bdf, log.jsonl, HMD\n"
      "screenshots, summary.json). Headless runs use a simulated clock that the EEG and\n"
      "the arm follow: the same session file and seed give the same recording. Ctrl+C ends\n"
      "the session and saves its summary (its \"ended\": finished, aborted, estop or fault).\n"
      "Exit status: 0 finished, 3 ended otherwise, 4 a --script failed.");
  run->add_option("--session", o->session,
                  "session file (JSON: the keys it changes; docs/settings.md, `arbci settings`)");
  run->add_flag("--headless", o->headless, "no window (automatic when there is no display)");
  schemaOverride(*run, "--trials", o->trials, session::sessionKey("paradigm.trials"));
  schemaOverride(*run, "--seed", o->seed, session::sessionKey("eeg.seed"));
  run->add_option("--out", o->out,
                  "session folder, which must not hold a session already; one that failed its "
                  "pre-flight is replaced, and a start that fails leaves nothing in it (default: "
                  "a new arbci-session-<date>-<time>)");
  run->add_flag("--overwrite", o->overwrite, "empty an existing --out folder first");
  run->add_flag("--realtime", o->realtime,
                "headless: the EEG, the frames and the arm on the wall clock (not reproducible)\n"
                "instead of a simulated clock as fast as the machine allows");
  run->add_flag("--exit-when-done", o->exit_when_done,
                "windowed: close the window once the session has ended (scripted runs); with\n"
                "--start-now and no --script nobody is expected at the window: what would wait\n"
                "for the experimenter (a failed pre-flight, objects out of view) ends the run");
  run->add_option("--script", o->script,
                  "windowed: a scripted experimenter replays FILE with real clicks on the\n"
                  "panels' buttons (wait \"PHASE\", click \"LABEL\", pause S, key ctrl+q,\n"
                  "screenshot F.png; see docs/render-ui.md). Exit status 4 when it fails")
      ->check(CLI::ExistingFile);
  run->add_flag("--start-now", o->start_now,
                "windowed: start at once, without the start screen's subject, session and run\n"
                "(headless runs always start at once)");
  // The start screen became the default; the old flag still parses, so lab scripts keep working.
  run->add_flag("--wait-for-start", o->wait_for_start,
                "windowed: the start screen waits for Start (the default; kept for old scripts)");
  run->add_option("--fault-wait", o->fault_wait_s,
                  "headless: seconds to wait for an experimenter after a robot fault")
      ->capture_default_str();
  addBidsOptions(run, o->bids, o->participant, o->bids_root, true);
  run->callback([o, &exit_code] { exit_code = runAndExport(*o); });
}

}  // namespace arbci::app
