// The EEG sources a session can acquire from, by name. A new source is a file in this folder
// that defines its Entry, and its line here.
#include "arbci/session/eeg_sources.h"

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

bool EegSettings::live() const {
  const EegSourceRegistry::Entry* entry = eegSources().find(source);
  return entry && entry->make.live;
}

}  // namespace arbci::session
