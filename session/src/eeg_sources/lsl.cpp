// A Lab Streaming Layer EEG stream (bci/lsl_source.h), found by name and/or type.
#include "arbci/bci/lsl_source.h"
#include "arbci/bci/settings.h"
#include "arbci/session/eeg_sources.h"

namespace arbci::session {

EegSourceRegistry::Entry lslEegSource() {
  EegSourceParts parts;
  parts.make = [](const EegSourceContext& c) -> std::unique_ptr<bci::EegSource> {
    bci::LslSourceSettings lsl;
    bci::lslSourceSchema().read(c.own, lsl);
    lsl.block_size = c.eeg.block_size;
    lsl.expected_rate_hz = c.eeg.rate_hz;
    lsl.config = c.lsl;
    try {
      return std::make_unique<bci::LslSource>(lsl);
    } catch (const bci::lsl::LslError& e) {
      throw SessionConfigError(c.session_file + ": eeg.source = \"lsl\": " + e.what());
    }
  };
  parts.live = true;
  return {"lsl", "a Lab Streaming Layer stream (eeg.lsl), on its sender's clock", parts,
          &bci::lslSourceSchema()};
}

}  // namespace arbci::session
