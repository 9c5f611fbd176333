// The EEG sources a session can acquire from, by eeg.source: the simulated subject, a recording
// replayed in real time, a Lab Streaming Layer stream, an eegdev amplifier.
#pragma once

#include <memory>
#include <string>

#include "arbci/bci/eeg_source.h"
#include "arbci/bci/lsl/config.h"
#include "arbci/bci/sample_clock.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

// The simulated subject a session with `eeg` (source "simulated") acquires from: its montage,
// rate, seed and line noise, the seed's drawn profile with eeg.erp_scale and eeg.errp_scale
// applied, and a virtual photodiode channel when one is named.
bci::SimulatedSubjectConfig simulatedSubjectOf(const EegSettings& eeg);

// Opens the source `eeg` names, paced by `clock` where it has no clock of its own. Throws
// SessionConfigError naming the key (`session_file` first) when it cannot.
std::unique_ptr<bci::EegSource> openEegSource(const EegSettings& eeg,
                                              const bci::lsl::LslConfig& lsl,
                                              std::shared_ptr<bci::SampleClock> clock,
                                              const std::string& session_file);

// A live simulated subject holds each block back this long, as a USB amplifier's buffer does;
// it knows its own delay, so its stamps stay true (a real amplifier's is measured by
// `arbci timing-check` and set as eeg.latency_ms).
constexpr double kSimulatedTransportS = 0.020;

}  // namespace arbci::session
