// A second process for the LSL tests: an ARBCI outlet streaming lslTestValue() (machine scope,
// loopback only). It waits for a client before sending, paces the samples at `--speed` times
// real time with timestamps t0 + index / rate, stops after `--stop-at` and then idles until
// killed (or `--linger` seconds pass).
//
//   lsl_outlet_helper NAME SOURCE_ID CHANNELS RATE SPEED START STOP_AT T0 [LINGER_S]
//   (T0 < 0: now). Prints "ready t0=<t0> port=<port>", then "done dropped=<n>".
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/lsl/outlet.h"
#include "support/lsl_test_signal.h"

using namespace arbci::bci::lsl;

int main(int argc, char** argv) {
  if (argc < 9) {
    std::fprintf(stderr,
                 "usage: %s NAME SOURCE_ID CHANNELS RATE SPEED START STOP_AT T0 [LINGER_S]\n",
                 argv[0]);
    return 2;
  }
  const std::string name = argv[1], source_id = argv[2];
  const int channels = std::stoi(argv[3]);
  const double rate = std::stod(argv[4]), speed = std::stod(argv[5]);
  const std::int64_t start = std::stoll(argv[6]), stop_at = std::stoll(argv[7]);
  double t0 = std::stod(argv[8]);
  const double linger = argc > 9 ? std::stod(argv[9]) : 120.0;
  LslConfig config;
  config.resolve_scope = "machine";
  StreamInfo info;
  info.name = name;
  info.type = "EEG";
  info.channel_count = channels;
  info.nominal_srate = rate;
  info.channel_format = ChannelFormat::Float32;
  info.source_id = source_id;
  for (int c = 0; c < channels; ++c)
    info.channels.push_back(
        {std::string("E").append(std::to_string(c + 1)), "microvolts", "EEG", ""});
  Outlet outlet(info, config);
  if (t0 < 0) t0 = localClock();
  std::printf("ready t0=%.9f port=%d\n", t0, outlet.info().v4data_port);
  std::fflush(stdout);
  for (int i = 0; i < 1000 && outlet.clients() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  constexpr int kChunk = 32;
  std::vector<float> chunk(static_cast<size_t>(kChunk) * channels);
  const double started = localClock();
  for (std::int64_t i = start; i < stop_at; i += kChunk) {
    const int n = static_cast<int>(std::min<std::int64_t>(kChunk, stop_at - i));
    for (int s = 0; s < n; ++s)
      for (int c = 0; c < channels; ++c)
        chunk[static_cast<size_t>(s) * channels + c] = arbci::test::lslTestValue(i + s, c);
    // Paced: sample i may go out (i - start) / (rate * speed) seconds after the start.
    const double due = started + static_cast<double>(i - start) / (rate * speed);
    const double wait = due - localClock();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    outlet.pushRaw(chunk.data(), n, t0 + static_cast<double>(i) / rate);
  }
  std::printf("done dropped=%lld\n", static_cast<long long>(outlet.droppedSamples()));
  std::fflush(stdout);
  std::this_thread::sleep_for(std::chrono::duration<double>(linger));
  return 0;
}
