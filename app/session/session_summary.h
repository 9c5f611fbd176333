// summary.json: how the session ended, the cycle's timing, the flashes as presented (SOA,
// durations, late frames, the EEG clock), the recording, every trial with the accuracies and bit
// rates, and the calibration's cross-validation.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/bci/evaluation.h"
#include "session/cycle_timing.h"
#include "session/eeg_stage.h"
#include "session/paradigm_stage.h"
#include "session/stimulus_timing.h"
#include "session/trial_record.h"

namespace arbci::app {

struct SessionFacts {
  std::string session_file;
  std::uint64_t seed = 0;
  std::string ended;       // finished, aborted, estop or fault
  std::string end_reason;  // in words
  double duration_s = 0.0;
  std::int64_t frames = 0;
  int object_choices = 0, cell_choices = 0;
};

nlohmann::json sessionSummary(const SessionFacts& facts, const CycleTiming& cycle,
                              const StimulusTiming& stimuli, const EegStage& eeg,
                              const std::vector<TrialRecord>& trials,
                              const std::optional<bci::EvaluationReport>& calibration);

// summary.json's "errp": what the ErrP classifier caught, vetoed and cost (docs/errp.md).
nlohmann::json errpSummary(const ParadigmStage::ErrpCounts& counts, double threshold,
                           const EegStage& eeg);

}  // namespace arbci::app
