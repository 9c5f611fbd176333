// lsl_bench: ARBCI's LSL inlet on loopback (machine scope). A forked child process is the outlet
// (ARBCI's), pushing as an amplifier app does; the parent is the inlet, as a session uses it
// (LslSource, polled every millisecond). Reported per configuration:
// - latency: from the outlet's push (its timestamp) to the block leaving LslSource::poll in
//   the parent (both read the same steady clock), p50 / p99 / max;
// - inlet cost: the parent's CPU time in the inlet's own threads (receive, time correction) plus
//   the polling thread's CPU inside LslSource::poll, per 15-sample block of the session, and as a
//   share of the 58.6 ms cycle. (The 1 ms polling loop itself is left out: the session's
//   acquisition thread runs it whatever the source.)
// Blocks of the first second are left out of the latency: they wait for the first
// time-correction estimate (about 0.6 s) before LslSource releases them.
// liblsl is not in Debian and is not built here: docs/eeg.md gives the same measurement of
// liblsl 1.16.2 taken by hand.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/lsl_source.h"

namespace {

using namespace arbci::bci;

struct Config {
  int channels;
  double rate;
  int chunk;  // samples per push
};

double cpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_utime.tv_usec * 1e-6 + usage.ru_stime.tv_sec +
         usage.ru_stime.tv_usec * 1e-6;
}

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

[[noreturn]] void runOutlet(const std::string& name, const Config& c, double seconds) {
  lsl::LslConfig config;
  config.resolve_scope = "machine";
  lsl::StreamInfo info;
  info.name = name;
  info.type = "EEG";
  info.channel_count = c.channels;
  info.nominal_srate = c.rate;
  lsl::Outlet outlet(info, config);
  for (int i = 0; i < 1000 && outlet.clients() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::vector<float> values(static_cast<size_t>(c.chunk) * c.channels, 1.0f);
  const double start = lsl::localClock();
  const long total = static_cast<long>(seconds * c.rate);
  for (long i = 0; i < total; i += c.chunk) {
    // A chunk leaves when its last sample has been taken, as from an amplifier.
    const double due = start + static_cast<double>(i + c.chunk) / c.rate;
    const double wait = due - lsl::localClock();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    // Stamped with the push instant of its last sample, so the latency is push to poll.
    outlet.pushRaw(values.data(), c.chunk, lsl::localClock() - (c.chunk - 1) / c.rate);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  _exit(0);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lsl_bench: ARBCI's LSL inlet on loopback: push-to-poll latency and CPU per block"};
  double seconds = 10.0;
  app.add_option("--seconds", seconds, "streaming time per configuration")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const std::vector<Config> configs{{8, 256, 1}, {8, 256, 15}, {64, 2048, 16}, {64, 2048, 1}};
  std::printf("ARBCI LSL, outlet and inlet in two processes on loopback, %.0f s each\n\n", seconds);
  std::printf(
      "| channels | rate (Hz) | samples per push | latency p50 ms | p99 ms | max ms | inlet CPU "
      "per 15-sample block | share of a 58.6 ms cycle |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Config& c : configs) {
    const std::string name = "lsl-bench-" + std::to_string(getpid()) + "-" +
                             std::to_string(c.channels) + "-" + std::to_string(c.chunk);
    const pid_t child = fork();
    if (child == 0) runOutlet(name, c, seconds);
    LslSourceSettings settings;
    settings.name = name;
    settings.block_size = 15;
    settings.config.resolve_scope = "machine";
    LslSource source(settings);
    std::vector<double> latencies;
    const double cpu0 = cpuSeconds(), main0 = threadCpuSeconds();
    double in_poll = 0.0;
    const auto started = std::chrono::steady_clock::now();
    long blocks = 0;
    const long expected = static_cast<long>(seconds * c.rate) / 15;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds + 10);
    while (blocks < expected - 2 && std::chrono::steady_clock::now() < deadline) {
      const double before = threadCpuSeconds();
      const std::vector<Block> polled = source.poll(256);
      in_poll += threadCpuSeconds() - before;
      for (const Block& b : polled) {
        ++blocks;
        // The block's last sample's stamp (on our clock) to now.
        const bool settled = std::chrono::steady_clock::now() - started > std::chrono::seconds(1);
        if (settled && !std::isnan(b.taken_host_s))
          latencies.push_back((lsl::localClock() - b.taken_host_s) * 1e3);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const double cpu = (cpuSeconds() - cpu0) - (threadCpuSeconds() - main0) + in_poll;
    int status = 0;
    waitpid(child, &status, 0);
    if (latencies.empty()) {
      std::printf("| %d | %.0f | %d | no blocks | | | | |\n", c.channels, c.rate, c.chunk);
      continue;
    }
    const double per_block_us = cpu / static_cast<double>(blocks) * 1e6;
    std::printf("| %d | %.0f | %d | %.2f | %.2f | %.2f | %.1f us | %.3f %% |\n", c.channels, c.rate,
                c.chunk, percentile(latencies, 0.5), percentile(latencies, 0.99),
                percentile(latencies, 1.0), per_block_us, per_block_us / 58594.0 * 100.0);
    std::fflush(stdout);
  }
  return 0;
}
