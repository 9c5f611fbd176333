// How well the simulated subject's error-related potentials can be told apart at all: the ErrP
// classifier's cross-validated AUC (5 contiguous blocks, as a session's calibration) on
// calibration blocks of growing size, per seed and method. The subject and the ErrP pipeline are
// the embedded session's (its montage, rate, notch, band, window, decimation, channels); feedbacks
// come every 3.5 s as in the calibration block (cue 1.5 s, result 1 s, pause 1 s), a quarter of
// them wrong in random order. An AUC that stops rising with thousands of feedbacks is the
// subject's, not the classifier's.
//   errp_ceiling_bench [--feedbacks 100,400,1600,6400] [--seeds 1] [--methods riemann,slda]
//                      [--errp-scale F] [--decimate-hz F] [--shift-ms F] [--xdawn-filters N]
//                      [--blocks N]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/sample_clock.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/session/eeg_sources.h"
#include "arbci/session/session_config.h"

using namespace arbci;

namespace {

constexpr double kFeedbackPeriodS = 3.5;  // cue 1.5 s + result 1 s + pause 1 s

// `blocks` calibration blocks of `feedbacks` feedbacks each (a quarter of each block wrong, in
// random order within it, as a session's calibration plans them) by the simulated subject of
// `eeg` with `seed`, as one recording whose stimuli are the feedbacks coded by class.
bci::Recording calibrationBlocks(session::EegSettings eeg, std::uint64_t seed, int feedbacks,
                                 int blocks) {
  eeg.seed = seed;
  eeg.photodiode_channel.clear();  // the ErrP pipeline's channels only
  const bci::SimulatedSubjectConfig config = session::simulatedSubjectOf(eeg);
  bci::SimulatedSubject subject(config, std::make_shared<bci::UnboundedClock>());

  std::mt19937 random(static_cast<std::uint32_t>(seed * 7919 + 17));
  std::vector<bool> wrong;
  for (int b = 0; b < blocks; ++b) {
    std::vector<bool> block(static_cast<size_t>(feedbacks), false);
    std::fill_n(block.begin(), feedbacks / 4, true);
    std::shuffle(block.begin(), block.end(), random);
    wrong.insert(wrong.end(), block.begin(), block.end());
  }
  feedbacks *= blocks;

  const int channels = static_cast<int>(config.montage.size());
  const auto period = static_cast<std::int64_t>(kFeedbackPeriodS * config.rate_hz);
  const std::int64_t total = (feedbacks + 1) * period;
  bci::Recording recording;
  recording.source = "simulated subject, seed " + std::to_string(seed);
  recording.format = "memory";
  recording.info = subject.info();
  recording.info.channels.resize(static_cast<size_t>(channels));
  std::vector<std::vector<float>> samples(static_cast<size_t>(channels));
  std::int64_t onset = period;  // the first feedback's presentation
  int done = 0;
  while (subject.samplesGenerated() < total) {
    if (done < feedbacks && subject.samplesGenerated() + config.block_size > onset) {
      const int target = 1 + static_cast<int>(random() % 4);
      int shown = target;
      if (wrong[static_cast<size_t>(done)]) {
        while (shown == target) shown = 1 + static_cast<int>(random() % 4);
      }
      subject.attend({target});
      subject.feedback(onset, {shown});
      bci::StimulusEvent event;
      event.sample = onset;
      event.code =
          wrong[static_cast<size_t>(done)] ? bci::kErrorFeedbackCode : bci::kCorrectFeedbackCode;
      event.target = wrong[static_cast<size_t>(done)];
      recording.stimuli.push_back(event);
      ++done;
      onset += period;
    }
    for (const bci::Block& block : subject.poll(1)) {
      for (int c = 0; c < channels; ++c) {
        for (int s = 0; s < block.samples; ++s)
          samples[static_cast<size_t>(c)].push_back(block.at(c, s));
      }
    }
  }
  recording.samples = static_cast<std::int64_t>(samples[0].size());
  for (const std::vector<float>& channel : samples)
    recording.data.insert(recording.data.end(), channel.begin(), channel.end());
  recording.parameters["Paradigm"] = "single stimulus, 2 stimuli";
  return recording;
}

// Epochs [first, end) of `data` as a dataset of their own (one contiguous calibration block).
bci::P300Dataset epochRange(const bci::P300Dataset& data, int first, int end) {
  bci::P300Dataset out = data;
  const auto take = [&](auto& v) {
    v = std::decay_t<decltype(v)>(v.begin() + first, v.begin() + end);
  };
  out.features = data.features.middleRows(first, end - first);
  take(out.target);
  take(out.code);
  take(out.sequence);
  take(out.selection);
  take(out.file);
  take(out.sample);
  out.selections.clear();
  for (const bci::SelectionEpochs& s : data.selections) {
    bci::SelectionEpochs kept{{}, s.target_codes, s.file};
    for (const int e : s.epochs)
      if (e >= first && e < end) kept.epochs.push_back(e - first);
    if (kept.epochs.empty()) continue;
    for (const int e : kept.epochs)
      out.selection[static_cast<size_t>(e)] = static_cast<int>(out.selections.size());
    out.selections.push_back(std::move(kept));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "Cross-validated AUC of the ErrP classifier on simulated calibration blocks of growing "
      "size: how separable the simulated subject's error-related potentials are"};
  std::vector<int> sizes{100, 400, 1600, 6400};
  std::vector<int> seeds{1};
  std::vector<std::string> methods{"riemann", "slda"};
  cli.add_option("--feedbacks", sizes, "calibration block sizes (a quarter of them wrong)")
      ->delimiter(',')
      ->check(CLI::Range(20, 100000))
      ->capture_default_str();
  cli.add_option("--seeds", seeds, "simulated subjects (the embedded session's is 1)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  double errp_scale = -1.0;
  cli.add_option("--errp-scale", errp_scale,
                 "the simulated ErrP's size against the subject's drawn one (default: the "
                 "embedded session's eeg.errp_scale)")
      ->check(CLI::Range(0.0, 100.0));
  double decimate_hz = 0.0;
  cli.add_option("--decimate-hz", decimate_hz,
                 "the features' rate (default: the embedded session's errp.decimate_hz)")
      ->check(CLI::Range(1.0, 256.0));
  double shift_ms = -1.0;
  cli.add_option("--shift-ms", shift_ms,
                 "shift-lda: the largest latency shift (default: the training setting's)")
      ->check(CLI::Range(0.0, 400.0));
  int xdawn_filters = 0;
  cli.add_option("--xdawn-filters", xdawn_filters,
                 "spatial filters (default: the embedded session's errp.xdawn_filters)")
      ->check(CLI::Range(1, 64));
  int blocks = 0;
  cli.add_option("--blocks", blocks,
                 "instead of one block per size: a recording of this many blocks of each size, "
                 "each block cross-validated on its own (mean, SD, range over the blocks)")
      ->check(CLI::Range(2, 1000));
  cli.add_option("--methods", methods, "ErrP classifiers (swlda, slda, xdawn, riemann, shift-lda)")
      ->delimiter(',')
      ->check(CLI::IsMember({"swlda", "slda", "xdawn", "riemann", "shift-lda"}))
      ->capture_default_str();
  CLI11_PARSE(cli, argc, argv);

  session::SessionConfig config = session::SessionConfig::load(std::nullopt);
  if (errp_scale >= 0.0) config.eeg.errp_scale = errp_scale;
  bci::PipelineSettings pipeline =
      config.errp.pipeline(config.classifier.pipeline, config.eeg.montage);
  if (decimate_hz > 0.0) pipeline.decimate_hz = decimate_hz;
  std::printf(
      "ErrP classifier, cross-validated AUC [95 %%] (5 contiguous blocks); the embedded session's "
      "subject (errp_scale %.2f) and ErrP pipeline (%.1f-%.1f Hz, %.0f-%.0f ms, %.0f Hz "
      "features, %zu channels); xDAWN filters per class %d\n%6s %9s %-8s %s\n",
      config.eeg.errp_scale, pipeline.filter.highpass_hz, pipeline.filter.lowpass_hz,
      pipeline.window.start_s * 1000.0, pipeline.window.end_s * 1000.0, pipeline.decimate_hz,
      pipeline.channels.size(), config.errp.xdawn_filters, "seed", "feedbacks", "method", "AUC");
  for (const int seed : seeds) {
    for (const int size : sizes) {
      const bci::Recording recording = calibrationBlocks(
          config.eeg, static_cast<std::uint64_t>(seed), size, std::max(1, blocks));
      const bci::P300Dataset whole = bci::buildDataset({recording}, pipeline);
      for (const std::string& method : methods) {
        bci::TrainingSettings training = config.errp.training();
        training.method = method;
        if (shift_ms >= 0.0) training.shift_ms = shift_ms;
        if (xdawn_filters > 0) training.xdawn.filters = xdawn_filters;
        if (blocks == 0) {
          try {
            const bci::CrossValidation cv = bci::crossValidate(whole, training);
            std::printf("%6d %9d %-9s %.3f [%.3f, %.3f]\n", seed, size, method.c_str(),
                        cv.report.auc, cv.report.auc_interval.low, cv.report.auc_interval.high);
          } catch (const std::invalid_argument& error) {
            std::printf("%6d %9d %-9s untrainable: %s\n", seed, size, method.c_str(), error.what());
          }
        } else {
          // A block a fold cannot train on is reported and left out of the mean, never an abort.
          std::vector<double> aucs;
          std::string untrainable;
          for (int b = 0; b < blocks; ++b) {
            try {
              const bci::CrossValidation cv =
                  bci::crossValidate(epochRange(whole, b * size, (b + 1) * size), training);
              aucs.push_back(cv.report.auc);
            } catch (const std::invalid_argument& error) {
              untrainable += " block " + std::to_string(b + 1) + ": " + error.what() + ";";
            }
          }
          const int n = static_cast<int>(aucs.size());
          double mean = 0.0, spread = 0.0;
          for (const double a : aucs) mean += a / std::max(1, n);
          for (const double a : aucs) spread += (a - mean) * (a - mean) / std::max(1, n - 1);
          if (n > 0)
            std::printf("%6d %9d %-9s mean %.3f SD %.3f range %.3f-%.3f over %d of %d blocks\n",
                        seed, size, method.c_str(), mean, std::sqrt(spread),
                        *std::min_element(aucs.begin(), aucs.end()),
                        *std::max_element(aucs.begin(), aucs.end()), n, blocks);
          if (!untrainable.empty())
            std::printf("%6d %9d %-9s untrainable:%s\n", seed, size, method.c_str(),
                        untrainable.c_str());
        }
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
