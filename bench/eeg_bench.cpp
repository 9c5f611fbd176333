// Cost per block (15 samples at 256 Hz, one 58.6 ms cycle) of the EEG stage of the cycle:
// common average reference, band-pass 0.5-30 Hz and 50 Hz notch, then epoching 0-800 ms around
// a flash every 180 ms (60 ms flash, 120 ms ISI), for 8, 16 and 64 channels.
#include <benchmark/benchmark.h>

#include <random>

#include "arbci/bci/epocher.h"
#include "arbci/bci/features.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/simulated_subject.h"

namespace {

using namespace arbci::bci;

void filterAndEpoch(benchmark::State& state) {
  const int channels = static_cast<int>(state.range(0));
  const SimulatedSubjectConfig subject;  // a session's rate
  SignalInfo info;
  info.rate_hz = subject.rate_hz;
  for (int c = 0; c < channels; ++c) info.channels.push_back("Ch" + std::to_string(c + 1));
  const PipelineSettings pipeline;  // a session's filters and window
  FilterChain filters(pipeline.filter, info);
  Epocher epocher(channels, info.rate_hz, pipeline.window);
  std::mt19937 random(1);
  std::normal_distribution<float> normal(0.0f, 10.0f);
  std::vector<Block> input(64, Block(0, channels, 15));
  for (Block& b : input) {
    for (float& v : b.data) v = normal(random);
  }
  std::int64_t sample = 0, next_flash = 0, epochs = 0;
  for (auto _ : state) {
    Block block = input[static_cast<size_t>(sample / 15) % input.size()];
    block.first_sample = sample;
    while (next_flash < sample + 15) {
      epocher.addEvent({next_flash, 1, false, 15});
      next_flash += 46;  // 180 ms
    }
    filters.process(block);
    epochs += static_cast<std::int64_t>(epocher.push(block).size());
    sample += 15;
    benchmark::DoNotOptimize(block.data.data());
  }
  state.counters["epochs/block"] =
      benchmark::Counter(static_cast<double>(epochs) / static_cast<double>(state.iterations()));
  state.SetLabel(std::to_string(channels) + " channels");
}

}  // namespace

BENCHMARK(filterAndEpoch)->Arg(8)->Arg(16)->Arg(64)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
