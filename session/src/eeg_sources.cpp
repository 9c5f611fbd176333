#include "arbci/session/eeg_sources.h"

#include "arbci/bci/eegdev_source.h"
#include "arbci/bci/file_source.h"
#include "arbci/bci/lsl_source.h"
#include "arbci/bci/recording.h"

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

std::unique_ptr<bci::EegSource> openEegSource(const EegSettings& eeg,
                                              const bci::lsl::LslConfig& lsl_config,
                                              std::shared_ptr<bci::SampleClock> clock,
                                              const std::string& session_file) {
  if (eeg.source == "lsl") {
    bci::LslSourceSettings lsl;
    lsl.name = eeg.lsl_name;
    lsl.type = eeg.lsl_type;
    lsl.resolve_timeout_s = eeg.lsl_resolve_timeout_s;
    lsl.block_size = eeg.block_size;
    lsl.expected_rate_hz = eeg.rate_hz;
    lsl.config = lsl_config;
    try {
      return std::make_unique<bci::LslSource>(lsl);
    } catch (const bci::lsl::LslError& e) {
      throw SessionConfigError(session_file + ": eeg.source = \"lsl\": " + e.what());
    }
  }
  if (eeg.source == "eegdev") {
    bci::EegdevSourceSettings device;
    device.device = eeg.eegdev_device;
    device.block_size = eeg.block_size;
    device.expected_rate_hz = eeg.rate_hz;
    try {
      return std::make_unique<bci::EegdevSource>(device);
    } catch (const bci::EegdevError& e) {
      throw SessionConfigError(session_file + ": eeg.source = \"eegdev\": " + e.what());
    }
  }
  if (eeg.source == "file") {
    bci::Recording replay = bci::readRecording(eeg.file);
    replay.stimuli.clear();  // the session presents its own stimuli
    return std::make_unique<bci::FileSource>(std::move(replay), clock, eeg.block_size);
  }
  return std::make_unique<bci::SimulatedSubject>(simulatedSubjectOf(eeg), clock);
}

}  // namespace arbci::session
