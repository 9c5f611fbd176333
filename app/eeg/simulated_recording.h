// A recording of the simulated subject in a copy task: selections of flash sequences, one cued
// target per selection, written to BDF+ with every stimulus and selection.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

namespace arbci::app {

struct SimulationOptions {
  double seconds = 60.0;
  std::string out;
  std::uint64_t seed = 1;
  double rate_hz = 256.0;
  std::string montage = "Fz,Cz,P3,Pz,P4,PO7,Oz,PO8";
  int stimuli = 4;            // single-stimulus paradigm (objects)
  int rows = 0, columns = 0;  // row/column paradigm when both are set
  int sequences = 10;
  double flash_ms = 60.0;
  double isi_ms = 120.0;
  double line_hz = 50.0;
  double alpha_hz = 10.0;
  bool paced = false;
};

struct SimulationSummary {
  std::int64_t samples = 0;
  int stimuli = 0, targets = 0, selections = 0;
};

// Throws CliError for bad options or an unwritable file; reports progress on `progress`.
SimulationSummary recordSimulation(const SimulationOptions& options, std::ostream& progress);

}  // namespace arbci::app
