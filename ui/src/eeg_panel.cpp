// The EEG panel: every channel scrolling (scale, time base, the session's filter on or off), the
// stimulus onsets and the photodiode channel marked, each channel's quality graded with its
// finding — over the window's EEG scope, fed from the cycle records; the grades are the records'
// own (SignalQualityStage's).
#include <imgui.h>

#include "arbci/ui/eeg_view.h"
#include "arbci/ui/panel_registry.h"

namespace arbci::ui {
namespace {

class EegPanel final : public Panel {
 public:
  const char* title() const override { return "EEG"; }
  void draw(const PanelInput& in) override {
    const bci::SignalScope* scope = in.window.eegScope();
    if (!scope || scope->endSample() == 0) {
      ImGui::TextDisabled("no EEG yet: the source has delivered nothing");
      return;
    }
    view_.draw(*scope, in.record.quality,
               in.settings.gates.thresholds(in.settings.classifier.pipeline.filter.notch_hz),
               in.settings.eeg.photodiode_channel, in.record.eeg.impedance);
  }

 private:
  EegView view_;
};

}  // namespace

PanelRegistry::Entry eegPanel() {
  PanelParts parts{[] { return std::make_unique<EegPanel>(); }};
  // Several seconds of the calibration's flashing: traces, onsets and quality to show.
  parts.shots.push_back({"eeg",
                         "twelve seconds into the calibration's flashing",
                         [](const session::CycleRecord& r) {
                           return r.paradigm.phase == bci::Phase::CalibrationFlashing &&
                                  r.time_s > 12.0;
                         },
                         {},
                         true});
  return {"eeg",
          "every EEG channel scrolling, the stimuli and the photodiode marked, and each channel's "
          "quality (flat, saturated, line noise, drift, RMS)",
          std::move(parts)};
}

}  // namespace arbci::ui
