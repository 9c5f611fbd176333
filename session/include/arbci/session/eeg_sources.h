// The EEG sources a session can acquire from, by eeg.source (eegSources(): docs/settings.md
// lists them): the simulated subject, a recording replayed in real time, a Lab Streaming Layer
// stream, an eegdev amplifier, a BrainVision Recorder RDA stream. Each is one file in
// session/src/eeg_sources/ with its own settings (the section eeg.<name>), and a line in its
// registry.cpp.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "arbci/bci/eeg_source.h"
#include "arbci/bci/lsl/config.h"
#include "arbci/bci/sample_clock.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/core/registry.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

// What a source is opened with.
struct EegSourceContext {
  const EegSettings& eeg;          // the keys every source shares (rate, block size, montage)
  const nlohmann::json& own;       // its own section, resolved by its schema ({} without one)
  const bci::lsl::LslConfig& lsl;  // lsl_api.cfg with the session's scope and peers
  std::shared_ptr<bci::SampleClock> clock;  // paces a source that has no clock of its own
  const std::string& session_file;          // for messages naming a key
};

struct EegSourceParts {
  // Opens it; throws SessionConfigError naming the key (session_file first) when it cannot.
  std::function<std::unique_ptr<bci::EegSource>(const EegSourceContext&)> make;
  // Runs on its own clock in real time (an amplifier): a session on it cannot be stepped.
  bool live = false;
  // How long it holds each block back, as a USB amplifier's buffer would (a simulation's own).
  double transport_lag_s = 0.0;
  // The session file's eeg section (resolved) lacks what it needs: the key and why; empty: none.
  std::function<std::optional<std::pair<std::string, std::string>>(const nlohmann::json& eeg)>
      required;
};
using EegSourceRegistry = core::Registry<EegSourceParts>;
const EegSourceRegistry& eegSources();

// A source opened for a session: the source, and the clock that paces it (stepped: the clock the
// acquisition advances each cycle; live: the wall clock, holding blocks back by the source's
// transport lag).
struct OpenedEegSource {
  std::unique_ptr<bci::EegSource> source;
  std::shared_ptr<bci::SampleClock> clock;
};
class Clock;
// Opens eeg.source from its registry entry with its own section; throws SessionConfigError
// naming the key (session_file first) when it is unknown or cannot be opened.
OpenedEegSource openEegSource(const EegSettings& eeg, const bci::lsl::LslConfig& lsl,
                              const Clock& clock, const std::string& session_file);

// The simulated subject a session with `eeg` (source "simulated") acquires from: its montage,
// rate, seed and line noise, the seed's drawn profile with eeg.erp_scale and eeg.errp_scale
// applied, and a virtual photodiode channel when one is named.
bci::SimulatedSubjectConfig simulatedSubjectOf(const EegSettings& eeg);

}  // namespace arbci::session
