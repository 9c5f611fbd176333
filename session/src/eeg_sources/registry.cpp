// The EEG sources a session can acquire from, by name. A new source is a file in this folder
// that defines its Entry, and its line here.
#include "arbci/session/eeg_sources.h"

#include "arbci/session/clock.h"

namespace arbci::session {

EegSourceRegistry::Entry simulatedEegSource();
EegSourceRegistry::Entry fileEegSource();
EegSourceRegistry::Entry lslEegSource();
EegSourceRegistry::Entry eegdevEegSource();
EegSourceRegistry::Entry rdaEegSource();

const EegSourceRegistry& eegSources() {
  static const EegSourceRegistry registry = [] {
    EegSourceRegistry r("EEG source", "eeg.source");
    r.add(simulatedEegSource());
    r.add(fileEegSource());
    r.add(lslEegSource());
    r.add(eegdevEegSource());
    r.add(rdaEegSource());
    return r;
  }();
  return registry;
}

OpenedEegSource openEegSource(const EegSettings& eeg, const bci::lsl::LslConfig& lsl,
                              const Clock& clock, const std::string& session_file) {
  const EegSourceRegistry::Entry* entry = eegSources().find(eeg.source);
  if (!entry)
    throw SessionConfigError(session_file + ": eeg.source = \"" + eeg.source +
                             "\" must be one of " + eegSources().list());
  OpenedEegSource opened;
  opened.clock = clock.sourceClock(entry->make.transport_lag_s);
  static const nlohmann::json none = nlohmann::json::object();
  const auto own = eeg.sources.find(eeg.source);
  const EegSourceContext context{eeg, own == eeg.sources.end() ? none : own->second, lsl,
                                 opened.clock, session_file};
  opened.source = entry->make.make(context);
  return opened;
}

bool EegSettings::live() const {
  const EegSourceRegistry::Entry* entry = eegSources().find(source);
  return entry && entry->make.live;
}

}  // namespace arbci::session
