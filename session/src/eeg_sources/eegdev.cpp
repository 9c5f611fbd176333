// An amplifier through eegdev (bci/eegdev_source.h): BioSemi, TOBI iA, or a file played by its
// datafile plugin.
#include "arbci/bci/eegdev_source.h"
#include "arbci/bci/settings.h"
#include "arbci/session/eeg_sources.h"

namespace arbci::session {

EegSourceRegistry::Entry eegdevEegSource() {
  EegSourceParts parts;
  parts.make = [](const EegSourceContext& c) -> std::unique_ptr<bci::EegSource> {
    bci::EegdevSourceSettings device;
    bci::eegdevSourceSchema().read(c.own, device);
    device.block_size = c.eeg.block_size;
    device.expected_rate_hz = c.eeg.rate_hz;
    try {
      return std::make_unique<bci::EegdevSource>(device);
    } catch (const bci::EegdevError& e) {
      throw SessionConfigError(c.session_file + ": eeg.source = \"eegdev\": " + e.what());
    }
  };
  parts.live = true;
  parts.required =
      [](const nlohmann::json& eeg) -> std::optional<std::pair<std::string, std::string>> {
    if (eeg["eegdev"]["device"].get<std::string>().empty())
      return std::pair{"eegdev.device",
                       "is required when eeg.source is \"eegdev\" (e.g. \"biosemi\", "
                       "\"datafile|path|/data/s01.bdf\")"};
    return std::nullopt;
  };
  return {"eegdev", "an amplifier through eegdev (eeg.eegdev.device), on its own clock", parts,
          &bci::eegdevSourceSchema()};
}

}  // namespace arbci::session
