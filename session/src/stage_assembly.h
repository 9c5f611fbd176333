// The wiring: which stage gets which part of the session file, in which order the stages run, and
// what one stage's construction tells another's settings (the cameras' models to tracking, the
// EEG channels to the classifiers). The one place that knows every stage.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "arbci/session/session.h"
#include "arbci/session/trigger_output.h"

namespace arbci::session {

// The session file's settings with the run's options over them (seed, trials, the timing
// check's flashes only).
SessionConfig configFor(SessionConfig config, const SessionOptions& options);
// The run's options as the session's sources allow: a live amplifier runs on its own clock, so a
// session on it cannot be stepped, whoever asked for it (a headless run, a screenshot).
SessionOptions optionsFor(SessionOptions options, const SessionConfig& config);

struct AssembledStages {
  std::vector<std::unique_ptr<Stage>> stages;  // in the order they run
  RobotStage* robot = nullptr;
  std::unique_ptr<TriggerOutput> trigger;  // eeg.trigger_out "serial": its port, open
};

// Throws SessionConfigError naming the key, or std::runtime_error with the reason.
AssembledStages assembleStages(const SessionConfig& config, const SessionOptions& options,
                               Clock& clock, const std::filesystem::path& folder,
                               const StageServices& services, const DisplayFactory& display);

}  // namespace arbci::session
