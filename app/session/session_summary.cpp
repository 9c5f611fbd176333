#include "session/session_summary.h"

#include <cmath>

namespace arbci::app {

nlohmann::json sessionSummary(const SessionFacts& facts, const CycleTiming& cycle,
                              const StimulusTiming& stimuli, const EegStage& eeg,
                              const std::vector<TrialRecord>& trials,
                              const std::optional<bci::EvaluationReport>& calibration) {
  nlohmann::json out = {
      {"session", facts.session_file},
      {"seed", facts.seed},
      {"ended", facts.ended},
      {"end_reason", facts.end_reason},
      {"duration_s", facts.duration_s},
      {"frames", facts.frames},
      {"cycle", cycle.toJson()},
      {"overruns", cycle.overruns()},
      {"timing", stimuli.summary(eeg.lostSamples(), eeg.clockDriftPpm(), eeg.clockJitterMs())},
      {"eeg",
       {{"recording", "recording.bdf"},
        {"samples", eeg.samplesRecorded()},
        {"lost_samples", eeg.lostSamples()},
        {"missed_epochs", eeg.missedEpochs()},
        {"discarded_epochs", eeg.discardedEpochs()},
        {"source", eeg.sourceLine()}}},
  };
  out.update(trialsSummary(trials, facts.object_choices, facts.cell_choices));
  if (calibration) {
    out["calibration"] = {{"selections", calibration->selections.size()},
                          {"auc", calibration->auc},
                          {"accuracy_by_sequences", calibration->accuracy}};
  }
  return out;
}

nlohmann::json errpSummary(const ParadigmStage::ErrpCounts& c, double threshold,
                           const EegStage& eeg) {
  nlohmann::json errp = {{"threshold", threshold},
                         {"classifier", eeg.hasErrpModel()},
                         {"decisions", c.decisions},
                         {"wrong_selections", c.wrong_shown},
                         {"wrong_caught", c.wrong_caught},
                         {"correct_selections", c.correct_shown},
                         {"correct_vetoed", c.correct_vetoed},
                         {"runner_up", c.runner_up},
                         {"repeated", c.repeats},
                         {"trials_skipped", c.skipped_trials},
                         {"correction_s", c.correction_s}};
  if (eeg.hasErrpModel() && !std::isnan(eeg.model()->errp_auc))
    errp["calibration_auc"] = eeg.model()->errp_auc;
  return errp;
}

}  // namespace arbci::app
