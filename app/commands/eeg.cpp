// `arbci eeg info|convert|simulate|stream|streams`: look into EEG files, convert them to BDF+,
// record the simulated subject, and play or list Lab Streaming Layer streams (eeg_lsl.cpp).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "arbci/bci/settings.h"
#include "arbci/session/settings_schema.h"
#include "commands/commands.h"
#include "eeg/simulated_recording.h"
#include "support/cli_error.h"
#include "support/output_path.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

bci::Recording read(const std::string& path, bool salvage) {
  try {
    bci::ReadOptions options;
    options.salvage_truncated = salvage;
    return bci::readRecording(path, options);
  } catch (const bci::RecordingError& error) {
    throw CliError(error.what());
  }
}

void printInfo(const bci::Recording& r) {
  std::cout << "file:      " << r.source << "\n"
            << "format:    " << r.format << "\n"
            << "channels:  " << r.info.channelCount() << " (";
  for (int c = 0; c < r.info.channelCount(); ++c) std::cout << (c ? " " : "") << r.info.channels[c];
  std::cout << ")\n"
            << "rate:      " << r.info.rate_hz << " Hz\n"
            << "samples:   " << r.samples << " (" << std::fixed << std::setprecision(2)
            << r.seconds() << " s)\n";
  if (r.truncated)
    std::cout << "truncated: " << r.truncation_note << "; read up to the last complete record\n";
  for (const std::string& note : r.notes) std::cout << "note:      " << note << "\n";
  std::map<int, std::pair<int, int>> by_code;  // code -> (count, targets)
  int targets = 0;
  for (const bci::StimulusEvent& e : r.stimuli) {
    ++by_code[e.code].first;
    if (e.target) {
      ++by_code[e.code].second;
      ++targets;
    }
  }
  std::cout << "stimuli:   " << r.stimuli.size() << " (" << targets << " targets)\n";
  for (const auto& [code, counts] : by_code) {
    std::cout << "  code " << std::setw(3) << code << ": " << std::setw(5) << counts.first << " ("
              << counts.second << " targets)\n";
  }
  std::cout << "other events: " << r.annotations.size() << "\n";
  std::map<std::string, int> by_text;
  for (const bci::Annotation& a : r.annotations) ++by_text[a.text.substr(0, a.text.find(' '))];
  for (const auto& [word, count] : by_text) std::cout << "  " << word << ": " << count << "\n";
  std::cout << "parameters: " << r.parameters.size() << "\n";
}

void convert(const std::string& in, const std::string& out, bool salvage) {
  const std::filesystem::path target(out);
  if (target.extension() != ".bdf")
    throw CliError(out + ": ARBCI writes BDF+ files; name the output *.bdf");
  ensureWritable(target);
  const bci::Recording r = read(in, salvage);
  try {
    std::map<std::string, std::string> parameters = r.parameters;
    parameters["SourceFile"] = std::filesystem::path(in).filename().string();
    bci::RecordingWriterOptions options;
    options.known_samples = r.samples;  // records that divide the signal: no padding
    bci::RecordingWriter writer(target, r.info, parameters, options);
    // Events go in with the samples they belong to, so no record waits for a backlog of them.
    std::vector<bci::StimulusEvent> stimuli = r.stimuli;
    std::vector<bci::Annotation> annotations = r.annotations;
    std::stable_sort(stimuli.begin(), stimuli.end(),
                     [](const auto& a, const auto& b) { return a.sample < b.sample; });
    std::stable_sort(annotations.begin(), annotations.end(),
                     [](const auto& a, const auto& b) { return a.sample < b.sample; });
    size_t next_stimulus = 0, next_annotation = 0;
    const int step = static_cast<int>(std::max(1.0, r.info.rate_hz));
    for (std::int64_t first = 0; first < r.samples; first += step) {
      const int count = static_cast<int>(std::min<std::int64_t>(step, r.samples - first));
      while (next_stimulus < stimuli.size() && stimuli[next_stimulus].sample < first + count)
        writer.addStimulus(stimuli[next_stimulus++]);
      while (next_annotation < annotations.size() &&
             annotations[next_annotation].sample < first + count)
        writer.addAnnotation(annotations[next_annotation++]);
      bci::Block block(first, r.info.channelCount(), count);
      for (int c = 0; c < block.channels; ++c) {
        for (int s = 0; s < count; ++s) block.at(c, s) = r.at(c, first + s);
      }
      writer.write(block);
    }
    for (; next_stimulus < stimuli.size(); ++next_stimulus)
      writer.addStimulus(stimuli[next_stimulus]);
    for (; next_annotation < annotations.size(); ++next_annotation)
      writer.addAnnotation(annotations[next_annotation]);
    writer.close();
    std::cout << "wrote " << out << ": " << r.info.channelCount() << " channels, " << r.samples
              << " samples, " << r.stimuli.size() << " stimuli, " << r.annotations.size()
              << " other events";
    if (writer.clippedSamples() > 0)
      std::cout << "; " << writer.clippedSamples() << " samples clipped to +-8000 uV";
    if (writer.paddedSamples() > 0) {
      std::cout << "; " << writer.paddedSamples()
                << " samples of padding end the last record (no record length divides the "
                   "signal; ARBCI's reader drops them)";
    }
    if (writer.shortenedAnnotations() > 0) {
      std::cout << "; " << writer.shortenedAnnotations()
                << " long parameters or events cut to fit a record:";
      for (const std::string& text : writer.shortenedTexts()) std::cout << " \"" << text << "...\"";
    }
    std::cout << "\n";
    // What the reader had to decide (outlier stamps, breaks, markers left out): said here too,
    // since the BDF alone cannot say it.
    for (const std::string& note : r.notes) std::cout << "note: " << note << "\n";
  } catch (const bci::RecordingError& error) {
    throw CliError(error.what());
  }
}

}  // namespace

void addEegCommand(CLI::App& root, int& exit_code) {
  CLI::App* eeg = root.add_subcommand(
      "eeg", "EEG files: information, conversion to BDF+, simulated recordings");
  eeg->require_subcommand(1);

  struct Options {
    std::string file, in, out;
    bool salvage = false;
    SimulationOptions simulation;
    std::optional<int> session_trials;  // --trials
  };
  auto options = std::make_shared<Options>();

  CLI::App* info =
      eeg->add_subcommand("info",
                          "Channels, rate, duration and event counts by code of an EEG file\n"
                          "(BCI2000 .dat, GDF, EDF(+), BDF(+), XDF).");
  info->add_option("FILE", options->file, "the recording")->required();
  info->add_flag("--salvage", options->salvage,
                 "read a file cut short up to its last complete record");
  info->callback([options, &exit_code] {
    printInfo(read(options->file, options->salvage));
    exit_code = 0;
  });

  CLI::App* conv = eeg->add_subcommand(
      "convert",
      "Convert an EEG file to BDF+ (samples, stimuli as \"Stim <code> T|N|U\",\n"
      "other events, parameters as \"Param name=value\").");
  conv->add_option("IN", options->in, "the recording to read")->required();
  conv->add_option("OUT", options->out, "the BDF+ file to write (*.bdf)")->required();
  conv->add_flag("--salvage", options->salvage,
                 "convert a file cut short up to its last complete record");
  conv->callback([options, &exit_code] {
    convert(options->in, options->out, options->salvage);
    exit_code = 0;
  });

  addEegStreamCommands(eeg, exit_code);
  CLI::App* sim =
      eeg->add_subcommand("simulate",
                          "Record the simulated subject in a copy task to BDF+: selections of\n"
                          "--sequences sequences of --stimuli flashing stimuli, one attended\n"
                          "target per selection (marked in the file). With --trials, a\n"
                          "session-shaped run instead: a calibration run, then trials of an\n"
                          "object selection and a grid selection, annotated as a session is.");
  SimulationOptions& s = options->simulation;
  const auto& subject = bci::subjectSchema();
  const auto& paradigm = bci::paradigmSchema();
  CLI::Option* seconds = sim->add_option("--seconds", s.seconds, "length of the recording")
                             ->check(CLI::Range(1.0, 86400.0));
  CLI::Option* trials =
      schemaOverride(*sim, "--trials", options->session_trials, paradigm.at("trials"))
          ->excludes(seconds);
  trials->description(trials->get_description() +
                      "; given, a session-shaped run of that many trials (its length follows)");
  schemaOption(*sim, "--calibration", s.calibration, paradigm.at("calibration_selections"),
               "with --trials")
      ->needs(trials);
  sim->add_option("--out", s.out, "BDF+ file to write")->required();
  schemaOption(*sim, "--seed", s.seed, subject.at("seed"), "the same seed, the same recording");
  schemaOption(*sim, "--rate", s.rate_hz, subject.at("rate_hz"));
  schemaOption(*sim, "--montage", s.montage, subject.at("montage"), "comma-separated");
  sim->add_option("--stimuli", s.stimuli, "stimuli flashed one at a time (objects)")
      ->capture_default_str()
      ->check(CLI::Range(2, 64));
  sim->add_option("--rows", s.rows,
                  "flash rows and columns of a ROWSxCOLUMNS matrix instead (with --columns)")
      ->check(CLI::Range(0, 32));
  sim->add_option("--columns", s.columns, "columns of the matrix")->check(CLI::Range(0, 32));
  schemaOption(*sim, "--sequences", s.sequences, paradigm.at("calibration_sequences"),
               "sequences per selection");
  schemaOption(*sim, "--flash-ms", s.flash_ms, paradigm.at("flash_ms"));
  schemaOption(*sim, "--isi-ms", s.isi_ms, paradigm.at("isi_ms"));
  schemaOption(*sim, "--line-hz", s.line_hz, subject.at("line_hz"));
  sim->add_option("--alpha-hz", s.alpha_hz, "alpha peak frequency")
      ->capture_default_str()
      ->check(CLI::Range(6.0, 14.0));
  schemaOption(*sim, "--erp-scale", s.erp_scale,
               *session::sessionSchema().find("eeg")->table->find("erp_scale"),
               "its N2 too; 0.5: half the drawn amplitude");
  sim->add_flag("--paced", s.paced,
                "run in real time (as a live session would) instead of as fast as possible");
  sim->callback([options, &exit_code] {
    ensureWritable(options->simulation.out);
    if (std::filesystem::path(options->simulation.out).extension() != ".bdf") {
      throw CliError(options->simulation.out + ": ARBCI records BDF+ files; name the output *.bdf");
    }
    options->simulation.trials = options->session_trials.value_or(0);
    if ((options->simulation.rows > 0) != (options->simulation.columns > 0))
      throw CliError("give both --rows and --columns");
    if (options->simulation.trials == 0 && options->simulation.seconds <= 0.0)
      throw CliError("give --seconds (a copy task) or --trials (a session-shaped run)");
    if (options->simulation.trials > 0 && options->simulation.rows > 0)
      throw CliError(
          "--trials flashes the session's objects (--stimuli) and its grid (world.grid); "
          "--rows and --columns are for a copy task");
    const SimulationSummary summary = recordSimulation(options->simulation, std::cerr);
    std::cout << "wrote " << options->simulation.out << ": " << summary.samples << " samples, "
              << summary.stimuli << " stimuli (" << summary.targets << " targets), "
              << summary.selections << " selections\n";
    exit_code = 0;
  });
}

}  // namespace arbci::app
