// Training time and per-epoch scoring time of each P300 method on BCI2000's eeg3_1.dat (720
// epochs, 8 channels x 15 bins), with the single-flash AUC on eeg3_2.dat trained on eeg3_1.
// Usage: p300_bench [DATA_DIR] (default: the shared data folder the build was configured with).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <string>

#include "arbci/bci/p300_model.h"

using namespace arbci::bci;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  CLI::App cli{
      "Training and scoring time of each P300 method on BCI2000's eeg3_1.dat, with the AUC on "
      "eeg3_2.dat"};
  std::string dir = std::string(ARBCI_SHARED_DATA_DIR) + "/eeg/bci2000_samplefiles";
  cli.add_option("data_dir", dir, "folder with eeg3_1.dat and eeg3_2.dat")
      ->check(CLI::ExistingDirectory)
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);
  try {
    const PipelineSettings pipeline = withMethodRate(PipelineSettings{}, "slda");  // 20 Hz
    auto start = Clock::now();
    const P300Dataset train = buildDataset({readRecording(dir + "/eeg3_1.dat")}, pipeline);
    const double prepare_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    const P300Dataset test = buildDataset({readRecording(dir + "/eeg3_2.dat")}, pipeline);
    std::printf(
        "P300 methods on eeg3_1.dat (%d epochs, %d features); reading, filtering and epoching: "
        "%.1f ms\n",
        train.epochs(), train.shape.size(), prepare_ms);
    std::printf("%-7s %12s %12s %16s %10s\n", "method", "train ms", "train + cv ms",
                "score us/epoch", "test AUC");
    for (const std::string method : {"swlda", "slda", "xdawn"}) {
      const int repeats = 5;
      double train_ms = 1e300;
      std::unique_ptr<Classifier> classifier;
      TrainingSettings settings;
      settings.method = method;
      for (int r = 0; r < repeats; ++r) {
        classifier = makeClassifier(settings);
        start = Clock::now();
        classifier->train(train.features, train.target, train.shape);
        train_ms = std::min(
            train_ms, std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      }
      start = Clock::now();
      trainModel(train, pipeline, settings);
      const double full_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      std::vector<double> scores(static_cast<size_t>(test.epochs()));
      double score_us = 1e300;
      for (int r = 0; r < repeats; ++r) {
        start = Clock::now();
        for (int i = 0; i < test.epochs(); ++i)
          scores[static_cast<size_t>(i)] = classifier->score(test.features.row(i).transpose());
        score_us = std::min(
            score_us, std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
                          test.epochs());
      }
      std::printf("%-7s %12.1f %12.1f %16.3f %10.3f\n", method.c_str(), train_ms, full_ms, score_us,
                  areaUnderCurve(scores, test.target));
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "p300_bench: %s\n", error.what());
    return 1;
  }
  return 0;
}
