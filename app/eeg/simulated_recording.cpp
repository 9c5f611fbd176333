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
#include "arbci/bci/selection_marks.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/bci/stimulus_sequence.h"
#include "arbci/core/seeds.h"
#include "arbci/session/session_config.h"
#include "support/cli_error.h"
#include "support/name_list.h"

namespace arbci::app {
namespace {

struct Selection {
  std::int64_t start = 0;  // sample at which the target is cued
  std::set<int> attended;
  std::string label;
  // A session-shaped run's: the phase annotation at the first flash.
  std::string phase;
  std::int64_t first_flash = 0;
};

struct Schedule {
  std::vector<Selection> selections;
  std::vector<bci::StimulusEvent> stimuli;
};

// One selection's flashes from `onset_s` on: `sequences` sequences of the layout's codes (each
// code plus `code_base`), labelled by `attended`. Returns the time after the last onset.
double flashSelection(const SimulationOptions& o, const bci::ParadigmLayout& layout,
                      bci::StimulusSequencer& sequencer, const std::set<int>& attended,
                      int code_base, double onset_s, Schedule& schedule) {
  const double soa = (o.flash_ms + o.isi_ms) / 1000.0;
  for (int sequence = 0; sequence < o.sequences; ++sequence) {
    for (int code : sequencer.next()) {
      bci::StimulusEvent e;
      e.sample = static_cast<std::int64_t>(std::llround(onset_s * o.rate_hz));
      e.code = code + code_base;
      e.target = attended.count(code) > 0;
      e.duration_samples = static_cast<int>(std::lround(o.flash_ms / 1000.0 * o.rate_hz));
      schedule.stimuli.push_back(e);
      onset_s += soa;
    }
  }
  (void)layout;
  return onset_s;
}

Schedule copyTask(const SimulationOptions& o, std::int64_t total_samples) {
  Schedule schedule;
  const bool matrix = o.rows > 0 && o.columns > 0;
  const bci::ParadigmLayout layout = matrix ? bci::ParadigmLayout::matrix(o.rows, o.columns)
                                            : bci::ParadigmLayout::single(o.stimuli);
  const int codes = layout.codes();
  const double soa = (o.flash_ms + o.isi_ms) / 1000.0;
  const double selection_seconds = 1.0 + o.sequences * codes * soa + 1.0;  // cue, flashes, rest
  const auto seed = static_cast<std::uint64_t>(o.seed);
  bci::StimulusSequencer sequencer(codes,
                                   core::seedOf(seed, core::RandomStream::RecordingFlashOrder));
  std::mt19937_64 random(core::seedOf(seed, core::RandomStream::RecordingChoices));
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
    flashSelection(o, layout, sequencer, selection.attended, 0, t + 1.0, schedule);
    schedule.selections.push_back(selection);
    t += selection_seconds;
  }
  return schedule;
}

// As a session runs (bci::Paradigm's phases and the session's annotations): the calibration run's
// cued object selections, then trials of an object selection and a grid selection, each chosen
// freely (drawn) and labelled by that choice; every selection `sequences` long (dynamic stopping
// is for the analysis to replay).
Schedule sessionTask(const SimulationOptions& o) {
  Schedule schedule;
  const bci::ParadigmLayout objects = bci::ParadigmLayout::single(o.stimuli);
  const bci::ParadigmLayout grid = bci::ParadigmLayout::matrix(o.grid_rows, o.grid_columns);
  const auto seed = static_cast<std::uint64_t>(o.seed);
  bci::StimulusSequencer object_order(objects.codes(),
                                      core::seedOf(seed, core::RandomStream::RecordingFlashOrder));
  bci::StimulusSequencer grid_order(grid.codes(),
                                    core::seedOf(seed, core::RandomStream::RecordingGridOrder));
  std::mt19937_64 random(core::seedOf(seed, core::RandomStream::RecordingChoices));
  const bci::ParadigmSettings paradigm;
  double t = 0.5;
  auto add = [&](bci::MarkedSelection mark, const bci::ParadigmLayout& layout,
                 bci::StimulusSequencer& order, bci::Phase phase, double lead_s) {
    Selection s;
    mark.number = static_cast<int>(schedule.selections.size()) + 1;
    s.start = static_cast<std::int64_t>(std::llround(t * o.rate_hz));
    s.attended = layout.drawTarget(random);
    s.label = bci::selectionMark(mark);
    s.phase = std::string(bci::kPhaseAnnotation) + bci::toString(phase);
    s.first_flash = static_cast<std::int64_t>(std::llround((t + lead_s) * o.rate_hz));
    const int base = layout.kind == bci::ParadigmLayout::Kind::RowColumn ? bci::kGridCodeBase : 0;
    t = flashSelection(o, layout, order, s.attended, base, t + lead_s, schedule);
    for (int code : std::set<int>(s.attended)) s.attended.insert(code + base);
    if (base > 0) std::erase_if(s.attended, [&](int code) { return code <= base; });
    schedule.selections.push_back(std::move(s));
    t += paradigm.pause_s;
  };
  for (int k = 0; k < o.calibration; ++k)
    add({0, bci::SelectionKind::Calibration, 0, 0, {}}, objects, object_order,
        bci::Phase::CalibrationFlashing, paradigm.cue_s);
  for (int trial = 1; trial <= o.trials; ++trial) {
    add({0, bci::SelectionKind::Objects, trial, 0, {}}, objects, object_order,
        bci::Phase::ObjectFlashing, paradigm.pause_s);
    add({0, bci::SelectionKind::Cells, trial, 0, {}}, grid, grid_order, bci::Phase::CellFlashing,
        paradigm.result_s);
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
  calibration = paradigm.calibration_selections;
  const session::GridSettings grid;
  grid_rows = grid.rows;
  grid_columns = grid.columns;
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
  const bool session_shaped = o.trials > 0;
  const Schedule schedule =
      session_shaped ? sessionTask(o)
                     : copyTask(o, static_cast<std::int64_t>(std::llround(o.seconds * o.rate_hz)));
  // A session-shaped run lasts until its last epoch is whole (and a second more).
  const auto total = session_shaped && !schedule.stimuli.empty()
                         ? schedule.stimuli.back().sample + 2 * static_cast<std::int64_t>(o.rate_hz)
                         : static_cast<std::int64_t>(std::llround(o.seconds * o.rate_hz));

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
  if (session_shaped) {
    // The session's own parameters for its two paradigms (session/src/stage_assembly.cpp).
    std::string map;
    for (int k = 1; k <= o.stimuli; ++k)
      map += std::to_string(k) + "=object " + std::to_string(k) + ";";
    for (int r = 1; r <= o.grid_rows; ++r)
      map += std::to_string(bci::kGridCodeBase + r) + "=row " + std::to_string(r) + ";";
    for (int c = 1; c <= o.grid_columns; ++c)
      map += std::to_string(bci::kGridCodeBase + o.grid_rows + c) + "=column " + std::to_string(c) +
             ";";
    map.pop_back();
    parameters["StimulusCodeMap"] = map;
    parameters["Paradigm"] = "single stimulus, " + std::to_string(o.stimuli) + " stimuli";
  }
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
        if (!s.phase.empty()) writer.addAnnotation({s.first_flash, s.phase, 0});
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
