// The session's recording: every block acquired, as it arrives, to a BDF+ file, with the events
// in the order they happened — the notes the stages made last cycle (phases, selections,
// tracking, robot steps), each flash with its label (Stim <code> T|N|U, grid codes as 100 + code)
// and measured duration once its last frame has passed, the feedback shown, and every stretch of
// lost samples; and the experimenter's notes (NoteRequest; also to the log). A write that fails
// (a full disk) ends the run as a fault, naming the file and the system's reason; what was
// written before stays readable.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "arbci/bci/recording_writer.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct RecordingSettings {
  std::filesystem::path path;
  bci::SignalInfo info;                           // every channel acquired
  std::map<std::string, std::string> parameters;  // "Param name=value" at time 0
};

class RecordingStage final : public Stage {
 public:
  // Creates the file; throws bci::RecordingError naming it when it cannot.
  RecordingStage(const RecordingSettings& settings, const StageServices& services);
  const char* name() const override { return "recording"; }
  void step(Cycle& cycle) override;
  // Notes the end and closes the file (a flash still lit is recorded with no duration).
  void stop(Cycle& cycle, const std::string& reason) override;
  void report(nlohmann::json& summary) const override;

 private:
  void record(Cycle& cycle);
  StageServices s_;
  std::unique_ptr<bci::RecordingWriter> writer_;
  std::map<std::int64_t, Flash> unrecorded_;  // by onset sample, until its duration is known
  std::string failed_;  // why a write failed (the run ended there); "" while all is written
  nlohmann::json notes_ = nlohmann::json::array();  // the experimenter's notes, for the summary
};

}  // namespace arbci::session
