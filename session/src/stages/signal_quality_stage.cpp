#include "arbci/session/stages/signal_quality_stage.h"

namespace arbci::session {
namespace {

// The grading looks at the raw signal; the scope's filtered copy is not used here.
bci::FilterSettings noFilter() {
  bci::FilterSettings f;
  f.highpass_hz = f.lowpass_hz = f.notch_hz = 0.0;
  f.common_average = false;
  return f;
}

}  // namespace

SignalQualityStage::SignalQualityStage(const SignalQualitySettings& settings)
    : scope_(settings.eeg_info, 2.0, noFilter(), settings.thresholds),
      channels_(settings.eeg_info.channels) {}

void SignalQualityStage::step(Cycle& cycle) {
  for (const bci::Block& block : cycle.record.eeg.eeg_blocks) scope_.append(block);
  cycle.record.quality.channels = channels_;
  cycle.record.quality.quality = scope_.quality();
}

}  // namespace arbci::session
