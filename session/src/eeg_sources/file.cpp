// A recording (any format arbci reads) replayed in real time as the session's EEG, its own
// stimuli left out: the session presents its own.
#include <filesystem>

#include "arbci/bci/file_source.h"
#include "arbci/bci/recording.h"
#include "arbci/session/eeg_sources.h"

namespace arbci::session {

EegSourceRegistry::Entry fileEegSource() {
  EegSourceParts parts;
  parts.make = [](const EegSourceContext& c) {
    bci::Recording replay = bci::readRecording(c.eeg.file);
    replay.stimuli.clear();  // the session presents its own stimuli
    return std::make_unique<bci::FileSource>(std::move(replay), c.clock, c.eeg.block_size);
  };
  parts.required =
      [](const nlohmann::json& eeg) -> std::optional<std::pair<std::string, std::string>> {
    if (eeg["file"].get<std::string>().empty())
      return std::pair{"file", "is required when source is \"file\""};
    return std::nullopt;
  };
  return {"file",
          "a recording (BDF, EDF, GDF, BCI2000, XDF) named by eeg.file, replayed in real time",
          std::move(parts)};
}

}  // namespace arbci::session
