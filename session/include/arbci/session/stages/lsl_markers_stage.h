// With lsl.markers: every note of the recording and every flash published as they happen on an
// LSL Markers stream (one string channel), stamped on the host clock that LSL uses, so a lab's
// LabRecorder can record the session's events beside the EEG.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/outlet.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct LslMarkersSettings {
  std::string stream;        // its name
  bci::lsl::LslConfig lsl;   // lsl_api.cfg with the session's scope and peers
  double eeg_rate_hz = 0.0;  // to place a note's sample on the host clock
  std::string session_file;  // for messages naming a key
  // The recording's parameters that describe the paradigm (bci::layoutParameters), in the
  // stream's description: a recorder's XDF carries the layout.
  std::vector<std::pair<std::string, std::string>> parameters;
};

class LslMarkersStage final : public Stage {
 public:
  // Opens the outlet; throws SessionConfigError naming lsl.markers when it cannot.
  LslMarkersStage(const LslMarkersSettings& settings, const StageServices& services);
  const char* name() const override { return "markers"; }
  void step(Cycle& cycle) override;
  void stop(Cycle& cycle, const std::string& reason) override;

 private:
  void publish(const Cycle& cycle, const std::string& text, double host_s);
  // A note at `sample`, stamped when that sample was taken.
  void publishNote(const Cycle& cycle, const bci::Annotation& note);
  LslMarkersSettings settings_;
  StageServices s_;
  std::unique_ptr<bci::lsl::Outlet> outlet_;
};

}  // namespace arbci::session
