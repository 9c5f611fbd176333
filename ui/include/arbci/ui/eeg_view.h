// The EEG panel's drawing on a signal scope, apart from where the scope comes from (the panel,
// the draw-cost bench): controls (scale, time base, filter), the quality legend, the traces with
// the stimulus onsets and the photodiode, and the quality table. The grades are the cycle
// record's (SignalQualityStage's, the ones the quality gate at Start reads), matched to the
// scope's channels by name: the view grades nothing itself. Call inside an ImGui window.
#pragma once

#include <imgui.h>

#include <string>
#include <vector>

#include "arbci/bci/signal_quality.h"
#include "arbci/bci/signal_scope.h"
#include "arbci/session/cycle.h"

namespace arbci::ui {

class EegView {
 public:
  // `quality`: the record's grades (EEG channels only); `thresholds`: what they were graded
  // against, for the legend; `photodiode`: the photodiode channel's name ("" for none);
  // `impedance`: the source's report ("" when it has none).
  void draw(const bci::SignalScope& scope, const session::QualityPart& quality,
            const bci::QualityThresholds& thresholds, const std::string& photodiode,
            const std::string& impedance);
  // The time base as the control would set it: the first it offers at or above `seconds`.
  void setTimeBase(double seconds);

 private:
  void drawControls();
  void drawQualityLegend(const bci::QualityThresholds& thresholds, const std::string& impedance);
  void drawTraces(const bci::SignalScope& scope);
  void drawQualityTable(const bci::SignalScope& scope);
  // Each of the scope's channels' grade from the record (none: not graded, the photodiode).
  void matchQuality(const bci::SignalScope& scope, const session::QualityPart& quality);
  int scale_ = 2;      // in the scale list: +/-50 uV a row
  int time_base_ = 1;  // 5 s
  bool filtered_ = true;
  std::string photodiode_;
  std::vector<const bci::SignalQuality*> quality_;  // per scope channel, this frame's
  std::vector<ImVec2> points_;                      // reused every frame
  std::vector<float> samples_;
};

}  // namespace arbci::ui
