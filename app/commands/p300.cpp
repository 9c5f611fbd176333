// `arbci train` and `arbci evaluate`: P300 models from recordings, cross-validated by selection,
// and their accuracy, selections and bit rate on other recordings.
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>

#include "arbci/bci/p300_model.h"
#include "commands/commands.h"
#include "eeg/p300_plots.h"
#include "eeg/p300_report.h"
#include "support/cli_error.h"
#include "support/name_list.h"
#include "support/output_path.h"

namespace arbci::app {
namespace {

std::vector<bci::Recording> readAll(const std::vector<std::string>& files) {
  std::vector<bci::Recording> recordings;
  for (const std::string& file : files) {
    try {
      recordings.push_back(bci::readRecording(file));
    } catch (const bci::RecordingError& error) {
      throw CliError(error.what());
    }
  }
  return recordings;
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

struct TrainOptions {
  std::vector<std::string> files;
  std::string out, channels, window_ms = "0,800", bci2000, plots;
  bci::TrainingSettings training;
  bci::PipelineSettings pipeline;
};

bci::EpochWindow parseWindow(const std::string& text) {
  double start = 0.0, end = 0.0;
  char comma = 0;
  std::istringstream in(text);
  if (!(in >> start >> comma >> end) || comma != ',' || !(end > start)) {
    throw CliError("--window-ms '" + text + "' must be START,END in milliseconds with END > START");
  }
  return {start / 1000.0, end / 1000.0};
}

void train(TrainOptions& o) {
  ensureWritable(o.out);
  if (!o.bci2000.empty()) ensureWritable(o.bci2000);
  o.pipeline.window = parseWindow(o.window_ms);
  o.pipeline.channels = splitNameList(o.channels);
  const bci::Progress progress = progressLine(std::cerr);
  bci::TrainingResult result;
  bci::P300Dataset data;
  try {
    data = bci::buildDataset(readAll(o.files), o.pipeline, progress);
    result = bci::trainModel(data, o.pipeline, o.training, progress);
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  result.model.provenance["created"] = utcNow();
  result.model.provenance["arbci_version"] = ARBCI_VERSION;
  try {
    result.model.save(o.out);
    if (!o.bci2000.empty()) {
      std::ofstream prm(o.bci2000);
      prm << result.model.bci2000Fragment();
      if (!prm) throw CliError("cannot write " + o.bci2000);
    }
  } catch (const bci::ModelError& error) {
    throw CliError(error.what());
  }
  std::cout << "trained " << o.training.method << " on " << data.epochs() << " epochs ("
            << data.shape.channels << " channels x " << data.shape.bins << " bins) from "
            << data.sources.size() << " file(s)";
  if (data.dropped_epochs > 0)
    std::cout << "; " << data.dropped_epochs << " flashes too close to a file's end left out";
  std::cout << "\n\ncross-validation, " << result.cross_validation.folds
            << " folds split by selection:\n";
  printReport(std::cout, result.cross_validation.report);
  if (!o.plots.empty()) {
    const auto written = writeP300Plots(o.plots, data, result.cross_validation.report,
                                        "cross-validated " + o.training.method);
    for (const auto& file : written) std::cout << "plot: " << file.string() << "\n";
  }
  std::cout << "model: " << o.out << "\n";
  if (!o.bci2000.empty()) std::cout << "BCI2000 parameters: " << o.bci2000 << "\n";
}

struct EvaluateOptions {
  std::string model, plots;
  std::vector<std::string> files;
  int sequences = 0;
  bci::StoppingRule dynamic{15, 2, 0.99};
};

void evaluate(EvaluateOptions& o) {
  bci::P300Model model;
  try {
    model = bci::P300Model::load(o.model);
  } catch (const bci::ModelError& error) {
    throw CliError(error.what());
  }
  const std::vector<bci::Recording> recordings = readAll(o.files);
  for (const bci::Recording& r : recordings) {
    try {
      model.checkCompatible(r.info, r.source);
    } catch (const bci::ModelError& error) {
      throw CliError(error.what());
    }
  }
  try {
    bci::P300Dataset data = bci::buildDataset(recordings, model.pipeline);
    std::vector<double> scores(static_cast<size_t>(data.epochs()));
    for (int i = 0; i < data.epochs(); ++i)
      scores[static_cast<size_t>(i)] = model.classifier->score(data.features.row(i).transpose());
    if (o.sequences > 0) {
      for (auto& s : data.selections) {
        std::erase_if(s.epochs, [&](int row) {
          return data.sequence[static_cast<size_t>(row)] >= o.sequences;
        });
      }
    }
    o.dynamic.max_sequences =
        std::min(o.dynamic.max_sequences, o.sequences > 0 ? o.sequences : o.dynamic.max_sequences);
    const bci::EvaluationReport report =
        bci::evaluateScores(data, scores, model.score_model, o.dynamic);
    std::cout << "model: " << o.model << " (" << model.method << ", trained on";
    for (const auto& f : model.provenance.value("training_files", nlohmann::json::array()))
      std::cout << " " << f.get<std::string>();
    std::cout << ")\n";
    printReport(std::cout, report);
    if (!o.plots.empty()) {
      for (const auto& file : writeP300Plots(o.plots, data, report, "evaluated " + model.method))
        std::cout << "plot: " << file.string() << "\n";
    }
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
}

}  // namespace

void addP300Commands(CLI::App& root, int& exit_code) {
  auto t = std::make_shared<TrainOptions>();
  CLI::App* train_cmd = root.add_subcommand(
      "train",
      "Train a P300 model (SWLDA as BCI2000, shrinkage LDA, or xDAWN + LDA) on\n"
      "recordings with known targets (BCI2000 .dat, ARBCI BDF+), cross-validated\n"
      "by selection.");
  train_cmd->add_option("FILES", t->files, "training recordings")->required();
  train_cmd->add_option("--method", t->training.method, "swlda, slda or xdawn")
      ->capture_default_str()
      ->check(CLI::IsMember({"swlda", "slda", "xdawn"}));
  train_cmd->add_option("--out", t->out, "model file to write (JSON)")->required();
  train_cmd->add_option("--channels", t->channels,
                        "comma-separated channels to use (default: all)");
  train_cmd->add_option("--window-ms", t->window_ms, "response window after the stimulus")
      ->capture_default_str();
  train_cmd
      ->add_option("--decimate-hz", t->pipeline.decimate_hz,
                   "feature rate after moving-average decimation")
      ->capture_default_str();
  train_cmd
      ->add_option("--highpass-hz", t->pipeline.filter.highpass_hz,
                   "Butterworth high-pass (0: none)")
      ->capture_default_str();
  train_cmd
      ->add_option("--lowpass-hz", t->pipeline.filter.lowpass_hz, "Butterworth low-pass (0: none)")
      ->capture_default_str();
  train_cmd->add_option("--notch-hz", t->pipeline.filter.notch_hz, "notch (0: none)")
      ->capture_default_str();
  train_cmd->add_flag("--car", t->pipeline.filter.common_average, "common average reference first");
  train_cmd->add_option("--folds", t->training.folds, "cross-validation folds (split by selection)")
      ->capture_default_str()
      ->check(CLI::Range(2, 100));
  train_cmd->add_option("--p-enter", t->training.swlda.p_enter, "SWLDA: p-value to enter")
      ->capture_default_str();
  train_cmd->add_option("--p-remove", t->training.swlda.p_remove, "SWLDA: p-value to remove")
      ->capture_default_str();
  train_cmd
      ->add_option("--max-features", t->training.swlda.max_features, "SWLDA: most features kept")
      ->capture_default_str();
  train_cmd->add_option("--xdawn-filters", t->training.xdawn.filters, "xDAWN: spatial filters kept")
      ->capture_default_str();
  train_cmd
      ->add_option("--certainty", t->training.dynamic.certainty,
                   "dynamic stopping: stop at this posterior probability")
      ->capture_default_str();
  train_cmd->add_option("--bci2000", t->bci2000,
                        "also write the model as a BCI2000 parameter fragment (.prm)");
  train_cmd->add_option("--plots", t->plots,
                        "folder for PNG plots (ERPs; accuracy and bit rate by sequences)");
  train_cmd->callback([t, &exit_code] {
    train(*t);
    exit_code = 0;
  });

  auto e = std::make_shared<EvaluateOptions>();
  CLI::App* eval_cmd =
      root.add_subcommand("evaluate",
                          "Apply a P300 model to recordings: selections, accuracy by number of\n"
                          "sequences, bit rate, and dynamic stopping.");
  eval_cmd->add_option("--model", e->model, "model file (from arbci train)")->required();
  eval_cmd->add_option("FILES", e->files, "recordings to evaluate")->required();
  eval_cmd->add_option("--sequences", e->sequences,
                       "use at most this many sequences per selection");
  eval_cmd
      ->add_option("--certainty", e->dynamic.certainty,
                   "dynamic stopping: stop at this posterior probability")
      ->capture_default_str();
  eval_cmd
      ->add_option("--min-sequences", e->dynamic.min_sequences,
                   "dynamic stopping: never before this many sequences")
      ->capture_default_str();
  eval_cmd->add_option("--plots", e->plots, "folder for PNG plots");
  eval_cmd->callback([e, &exit_code] {
    evaluate(*e);
    exit_code = 0;
  });
}

}  // namespace arbci::app
