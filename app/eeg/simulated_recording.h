// A recording of the simulated subject in a copy task: selections of flash sequences, one cued
// target per selection, written to BDF+ with every stimulus and selection.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace arbci::app {

// The subject's and the paradigm's options default to a session's (bci/settings.h).
struct SimulationOptions {
  SimulationOptions();
  double seconds = 0.0;  // a copy task's length
  std::string out;
  int seed;
  double rate_hz;
  std::vector<std::string> montage;
  int stimuli = 4;            // single-stimulus paradigm (objects)
  int rows = 0, columns = 0;  // row/column paradigm when both are set
  int sequences;              // a calibration selection's
  double flash_ms;
  double isi_ms;
  double line_hz;
  double alpha_hz;
  // > 0: a session-shaped run instead of a copy task (its length follows; `seconds` unused):
  // `calibration` cued object selections, then `trials` trials of an object selection and a
  // selection on the grid_rows x grid_columns grid (codes 100 + row, 100 + rows + column), each
  // annotated as a session annotates it (bci/selection_marks.h) and labelled by a drawn choice.
  int trials = 0;
  int calibration;
  int grid_rows, grid_columns;
  bool paced = false;
  double erp_scale;  // the subject's N2/P3 amplitudes scaled (a weaker responder below 1)
};

struct SimulationSummary {
  std::int64_t samples = 0;
  int stimuli = 0, targets = 0, selections = 0;
};

// Throws CliError for bad options or an unwritable file; reports progress on `progress`.
SimulationSummary recordSimulation(const SimulationOptions& options, std::ostream& progress);

}  // namespace arbci::app
