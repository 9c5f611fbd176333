// The first stage of each cycle: the frame drawn last cycle, once presented, as the screen showed
// it. Each flash's onset is the presentation of the first frame that showed it and its duration
// runs to the first frame that no longer does, both on the EEG sample clock; the photodiode patch
// as the frame showed it; late frames (more than a period after they were due) are logged, and a
// display that cannot hold its rate is said once.
#pragma once

#include "arbci/session/stage.h"
#include "arbci/session/stimulus_timing.h"

namespace arbci::session {

struct PresentationSettings {
  bci::ParadigmSettings paradigm;  // the nominal frame rate and SOA
  double eeg_rate_hz = 0.0;
};

class PresentationStage final : public Stage {
 public:
  PresentationStage(const PresentationSettings& settings, const StageServices& services);
  const char* name() const override { return "presentation"; }
  void step(Cycle& cycle) override;
  // The last frame drawn, if it was presented before the run ended.
  void stop(Cycle& cycle, const std::string& reason) override;
  // summary.json's "timing" (the EEG clock's figures are the acquisition's).
  void report(nlohmann::json& summary) const override;

 private:
  void warnIfDisplayTooSlow(double at_s);
  PresentationSettings settings_;
  StageServices s_;
  StimulusTiming timing_;
  bool patch_lit_ = false;  // as the last presented frame showed it
  bool warned_slow_display_ = false;
  std::optional<double> last_time_s_;  // the last cycle's session time
};

}  // namespace arbci::session
