// Each EEG channel's quality, graded over the last two seconds of raw signal as the EEG panel
// grades it (bci/signal_quality.h: flat, saturated, line noise at the notch's frequency, drift,
// RMS), on the record every cycle: the quality gate at Start reads it there, and so may a panel.
#pragma once

#include "arbci/bci/signal_scope.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct SignalQualitySettings {
  bci::SignalInfo eeg_info;  // the EEG channels only (never the photodiode)
  bci::QualityThresholds thresholds;
};

class SignalQualityStage final : public Stage {
 public:
  explicit SignalQualityStage(const SignalQualitySettings& settings);
  const char* name() const override { return "signal_quality"; }
  void step(Cycle& cycle) override;

 private:
  bci::SignalScope scope_;
  std::vector<std::string> channels_;
};

}  // namespace arbci::session
