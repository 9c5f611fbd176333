// Selections over many simulated trials with the default subject and dynamic stopping: object and
// cell accuracy with 95 % (Wilson) intervals, the time per selection measured from the presented
// flash onsets, and the bit rate counted two ways: over the flashing only, and over all of a
// trial's time (cues, pauses, feedback, the robot). Headless, simulated clock.
// Usage: selection_bench [--trials N] [--seed S] [--still-head]   (--help)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"
#include "hmd/open_session.h"

using namespace arbci;

namespace {

struct Interval {
  double low, high;
};

// Wilson's score interval: honest near 100 %, where the normal approximation is not.
Interval wilson(int right, int n) {
  if (n == 0) return {0.0, 1.0};
  const double z = 1.959964, p = static_cast<double>(right) / n;
  const double centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
  const double half = z * std::sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / (1.0 + z * z / n);
  return {centre - half, centre + half};
}

void row(const char* what, const nlohmann::json& rate, int right, int made) {
  const Interval ci = wilson(right, made);
  std::printf("%-8s %4d/%-4d %7.3f  [%.3f, %.3f]  %8.2f s  %8.2f bits/min\n", what, right, made,
              made ? static_cast<double>(right) / made : 0.0, ci.low, ci.high,
              rate.is_null() ? 0.0 : rate["seconds_per_selection"].get<double>(),
              rate.is_null() ? 0.0 : rate["bits_per_minute"].get<double>());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Selection accuracy, time and bit rate over many simulated trials"};
  int trials = 100;
  long long seed = 1;
  bool still_head = false;
  cli.add_option("--trials", trials, "online trials")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cli.add_option("--seed", seed, "seed of the subject, intentions and world")
      ->check(CLI::Range(0LL, 1LL << 30))
      ->capture_default_str();
  cli.add_flag("--still-head", still_head,
               "no head motion (the cameras render only when the arm moves: several times faster)");
  CLI11_PARSE(cli, argc, argv);
  try {
    session::SessionConfig config = session::SessionConfig::load(std::nullopt);
    if (still_head) config.cameras.head_motion_m = config.cameras.head_motion_deg = 0.0;
    config.intended.clear();  // random intentions for the seed, as many as trials
    auto context = render::createHeadlessContext({64, 64});
    session::SessionOptions options;
    options.folder = std::filesystem::temp_directory_path() /
                     ("arbci-selection-bench-" + std::to_string(::getpid()));
    options.trials = trials;
    options.seed = static_cast<std::uint64_t>(seed);
    options.max_session_s = 1e6;
    options.progress = &std::cerr;
    app::OpenedSession opened = app::openSession(config, options, *context);
    session::Session& session = *opened.session;
    const nlohmann::json s = session.run();
    int objects_right = 0, objects_made = 0, cells_right = 0, cells_made = 0;
    for (const session::TrialRecord& t : *session.last().paradigm.trials) {
      if (t.selected_object >= 0) {
        ++objects_made;
        objects_right += t.selected_object == t.intended_object;
      }
      if (t.selected_cell.first > 0) {
        ++cells_made;
        cells_right += t.selected_cell == t.intended_cell;
      }
    }
    std::printf(
        "\n%d trials, seed %lld, %s head, default subject, dynamic stopping (certainty %.3f,"
        " %d-%d sequences); ended: %s\n",
        trials, seed, still_head ? "still" : "moving", config.paradigm.certainty,
        config.paradigm.min_sequences, config.paradigm.sequences, session.endReason().c_str());
    std::printf("%-8s %9s %7s  %-16s  %10s  %s\n", "", "right", "acc", "95 % interval",
                "per select", "flash-only rate");
    row("objects", s["objects"], objects_right, objects_made);
    row("cells", s["cells"], cells_right, cells_made);
    const auto& all = s["all_inclusive"];
    if (!all.is_null())
      std::printf(
          "all-inclusive: %d completed trials, %.2f s per trial, %.2f s per selection, "
          "%.2f bits/min\n",
          all["completed_trials"].get<int>(), all["seconds_per_trial"].get<double>(),
          all["seconds_per_selection"].get<double>(), all["bits_per_minute"].get<double>());
    const auto& t = s["timing"];
    std::printf(
        "timing: SOA median %.2f ms (configured %.0f), flash median %.2f ms, late frames %lld,"
        " lost samples %lld\n",
        t["soa_ms"]["median"].get<double>(), t["soa_ms"]["configured"].get<double>(),
        t["flash_ms"]["median"].get<double>(), t["late_frames"].get<long long>(),
        t["lost_samples"].get<long long>());
    std::error_code ignored;
    std::filesystem::remove_all(options.folder, ignored);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "selection_bench: %s\n", error.what());
    return 1;
  }
  return 0;
}
