// The simulated subject (bci/simulated_subject.h): the session's default EEG, paced by the
// session's clock, answering the flashes it attends with a P300 and wrong feedback with an ErrP.
#include "arbci/session/eeg_sources.h"

namespace arbci::session {

bci::SimulatedSubjectConfig simulatedSubjectOf(const EegSettings& eeg) {
  bci::SimulatedSubjectConfig subject;
  subject.montage = eeg.montage;
  subject.rate_hz = eeg.rate_hz;
  subject.block_size = eeg.block_size;
  subject.seed = eeg.seed;
  subject.line_hz = eeg.line_hz;
  subject.photodiode = !eeg.photodiode_channel.empty();
  subject.photodiode_channel = eeg.photodiode_channel;
  bci::SubjectProfile profile = bci::SubjectProfile::drawn(eeg.seed);
  profile.p3_amplitude_uv *= eeg.erp_scale;
  profile.n2_amplitude_uv *= eeg.erp_scale;
  profile.errp_ne_amplitude_uv *= eeg.errp_scale;
  profile.errp_pe_amplitude_uv *= eeg.errp_scale;
  subject.profile = profile;
  return subject;
}

EegSourceRegistry::Entry simulatedEegSource() {
  EegSourceParts parts;
  parts.make = [](const EegSourceContext& c) {
    return std::make_unique<bci::SimulatedSubject>(simulatedSubjectOf(c.eeg), c.clock);
  };
  // A live simulated subject holds each block back as a USB amplifier's buffer does; it knows its
  // own delay, so its stamps stay true (a real amplifier's is measured by `arbci timing-check`
  // and set as eeg.latency_ms).
  parts.transport_lag_s = 0.020;
  return {"simulated",
          "the simulated subject: eeg.montage at eeg.rate_hz, a P300 to the flashes it attends "
          "(eeg.erp_scale), an ErrP to wrong feedback (eeg.errp_scale), a virtual photodiode",
          std::move(parts)};
}

}  // namespace arbci::session
