// The cycle's per-stage time on the simulated session (headless, EGL on Mesa llvmpipe): the
// embedded default world (head motion: the cameras re-render every camera frame) and the same
// with a still head. Prints p50/p90/p99/max per stage against the block budget (58.6 ms).
// Usage: session_bench [TRIALS]   (default 1; each run includes its calibration run; --help)
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"
#include "hmd/open_session.h"

using namespace arbci;

namespace {

void run(const char* name, session::SessionConfig config, int trials) {
  auto context = render::createHeadlessContext({64, 64});
  session::SessionOptions options;
  options.folder = std::filesystem::temp_directory_path() /
                   ("arbci-session-bench-" + std::to_string(::getpid()));
  options.trials = trials;
  app::OpenedSession opened = app::openSession(config, options, *context);
  session::Session& session = *opened.session;
  const auto start = std::chrono::steady_clock::now();
  session.run();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const session::CycleTiming& t = session.timing();
  std::printf("\n%s: %zu cycles, %.1f s of session in %.1f s (%.1fx real time), ended: %s\n", name,
              t.cycles(), session.time(), wall, session.time() / wall, session.endReason().c_str());
  std::printf("%-10s %9s %9s %9s %9s %9s\n", "stage", "mean ms", "p50 ms", "p90 ms", "p99 ms",
              "max ms");
  auto row = [](const std::string& stage, const session::Percentiles& p) {
    std::printf("%-10s %9.3f %9.3f %9.3f %9.3f %9.3f\n", stage.c_str(), p.mean, p.p50, p.p90, p.p99,
                p.max);
  };
  for (const auto& [stage, p] : t.stagePercentiles()) row(stage, p);
  row("total", t.totalPercentiles());
  std::printf("overruns (> %.1f ms): %d of %zu cycles\n", t.budgetMs(), t.overruns(), t.cycles());
  std::error_code ignored;
  std::filesystem::remove_all(options.folder, ignored);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "The cycle's per-stage time on the simulated session, with head motion and with a still "
      "head"};
  int trials = 1;
  cli.add_option("trials", trials, "online trials per run (each run also has its calibration run)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  try {
    session::SessionConfig config = session::SessionConfig::load(std::nullopt);
    run("simulated session (embedded default: head motion, camera noise, lens distortion)", config,
        trials);
    config.cameras.head_motion_m = 0.0;
    config.cameras.head_motion_deg = 0.0;
    run("the same with a still head (frames re-rendered only when the robot moves)", config,
        trials);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "session_bench: %s\n", error.what());
    return 1;
  }
  return 0;
}
