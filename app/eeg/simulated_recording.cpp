#include "eeg/simulated_recording.h"

#include <chrono>
#include <cmath>
#include <random>
#include <set>
#include <thread>

#include "arbci/bci/paradigm.h"
#include "arbci/bci/paradigm_layout.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/bci/stimulus_sequence.h"
#include "arbci/session/session_config.h"
#include "support/cli_error.h"
#include "support/name_list.h"

namespace arbci::app {
namespace {

struct Selection {
  std::int64_t start = 0;  // sample at which the target is cued
  std::set<int> attended;
  std::string label;
};

struct Schedule {
  std::vector<Selection> selections;
  std::vector<bci::StimulusEvent> stimuli;
};

Schedule copyTask(const SimulationOptions& o, std::int64_t total_samples) {
  Schedule schedule;
  const bool matrix = o.rows > 0 && o.columns > 0;
  const bci::ParadigmLayout layout = matrix ? bci::ParadigmLayout::matrix(o.rows, o.columns)
                                            : bci::ParadigmLayout::single(o.stimuli);
  const int codes = layout.codes();
  const double soa = (o.flash_ms + o.isi_ms) / 1000.0;
  const double selection_seconds = 1.0 + o.sequences * codes * soa + 1.0;  // cue, flashes, rest
  bci::StimulusSequencer sequencer(codes, o.seed + 1);
  std::mt19937_64 random(o.seed + 2);
  double t = 0.5;
  while ((t + selection_seconds) * o.rate_hz <= static_cast<double>(total_samples)) {
    Selection selection;
    selection.start = static_cast<std::int64_t>(std::llround(t * o.rate_hz));
    selection.attended = layout.drawTarget(random);
    selection.label = "Selection " + std::to_string(schedule.selections.size() + 1) + " target ";
    if (matrix) {
      const int row = *selection.attended.begin(), column = *selection.attended.rbegin() - o.rows;
      selection.label += "row " + std::to_string(row) + " column " + std::to_string(column);
    } else {
      selection.label += std::to_string(*selection.attended.begin());
    }
    double onset = t + 1.0;
    for (int sequence = 0; sequence < o.sequences; ++sequence) {
      for (int code : sequencer.next()) {
        bci::StimulusEvent e;
        e.sample = static_cast<std::int64_t>(std::llround(onset * o.rate_hz));
        e.code = code;
        e.target = selection.attended.count(code) > 0;
        e.duration_samples = static_cast<int>(std::lround(o.flash_ms / 1000.0 * o.rate_hz));
        schedule.stimuli.push_back(e);
        onset += soa;
      }
    }
    schedule.selections.push_back(selection);
    t += selection_seconds;
  }
  return schedule;
}

}  // namespace

SimulationOptions::SimulationOptions() {
  const bci::SimulatedSubjectConfig subject;
  const bci::ParadigmSettings paradigm;
  seed = static_cast<int>(subject.seed);
  rate_hz = subject.rate_hz;
  montage = subject.montage;
  sequences = paradigm.calibration_sequences;
  flash_ms = paradigm.flash_ms;
  isi_ms = paradigm.isi_ms;
  line_hz = subject.line_hz;
  alpha_hz = subject.alpha_hz;
  erp_scale = session::EegSettings().erp_scale;
}

SimulationSummary recordSimulation(const SimulationOptions& o, std::ostream& progress) {
  bci::SimulatedSubjectConfig config;
  config.montage = o.montage;
  if (config.montage.empty()) throw CliError("--montage names no channels");
  config.rate_hz = o.rate_hz;
  config.seed = static_cast<std::uint64_t>(o.seed);
  config.line_hz = o.line_hz;
  config.alpha_hz = o.alpha_hz;
  bci::SubjectProfile profile = bci::SubjectProfile::drawn(config.seed);
  profile.p3_amplitude_uv *= o.erp_scale;
  profile.n2_amplitude_uv *= o.erp_scale;
  config.profile = profile;
  std::shared_ptr<bci::SampleClock> clock;
  auto manual = std::make_shared<bci::ManualClock>();
  if (o.paced) {
    clock = std::make_shared<bci::WallClock>();
  } else {
    clock = manual;
  }
  bci::SimulatedSubject subject(config, clock);
  const auto total = static_cast<std::int64_t>(std::llround(o.seconds * o.rate_hz));
  const Schedule schedule = copyTask(o, total);

  std::map<std::string, std::string> parameters = {
      {"Source", "ARBCI simulated subject"},
      {"Seed", std::to_string(o.seed)},
      {"Paradigm", o.rows > 0
                       ? "row/column " + std::to_string(o.rows) + "x" + std::to_string(o.columns)
                       : "single stimulus, " + std::to_string(o.stimuli) + " stimuli"},
      {"NumberOfSequences", std::to_string(o.sequences)},
      {"StimulusDuration", std::to_string(o.flash_ms) + "ms"},
      {"ISIDuration", std::to_string(o.isi_ms) + "ms"},
      {"P3Amplitude", std::to_string(subject.profile().p3_amplitude_uv) + "uV"},
      {"P3Latency", std::to_string(subject.profile().p3_latency_s * 1000.0) + "ms"},
  };
  SimulationSummary summary;
  try {
    bci::RecordingWriter writer(o.out, subject.info(), parameters);
    size_t next_stimulus = 0, next_selection = 0;
    int last_percent = -1;
    while (subject.samplesGenerated() < total) {
      const std::int64_t block_end = subject.samplesGenerated() + subject.info().block_size;
      // Cue and present what falls into the next block before it is generated.
      while (next_selection < schedule.selections.size() &&
             schedule.selections[next_selection].start < block_end) {
        const Selection& s = schedule.selections[next_selection++];
        subject.attend(s.attended);
        writer.addAnnotation({s.start, s.label, 0});
        ++summary.selections;
      }
      while (next_stimulus < schedule.stimuli.size() &&
             schedule.stimuli[next_stimulus].sample < block_end) {
        const bci::StimulusEvent& e = schedule.stimuli[next_stimulus++];
        subject.present(e);
        writer.addStimulus(e);
        ++summary.stimuli;
        summary.targets += e.target ? 1 : 0;
      }
      if (o.paced) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      } else {
        manual->advanceTo(static_cast<double>(block_end) / o.rate_hz);
      }
      for (const bci::Block& block : subject.poll(1)) writer.write(block);
      const int percent =
          static_cast<int>(100 * subject.samplesGenerated() / std::max<std::int64_t>(total, 1));
      if (percent / 10 != last_percent / 10) {
        progress << "\rsimulating: " << percent << "%" << std::flush;
        last_percent = percent;
      }
    }
    progress << "\n";
    writer.close();
    summary.samples = writer.samplesWritten();
  } catch (const bci::RecordingError& error) {
    throw CliError(error.what());
  }
  return summary;
}

}  // namespace arbci::app
