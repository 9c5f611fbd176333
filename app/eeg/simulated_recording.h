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
  double seconds = 60.0;
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
