// The EEG panel's drawing on a signal scope, apart from where the scope comes from (the panel,
// the draw-cost bench): controls (scale, time base, filter), the quality legend, the traces with
// the stimulus onsets and the photodiode, and the quality table. Call inside an ImGui window.
#pragma once

#include <imgui.h>

#include <string>
#include <vector>

#include "arbci/bci/signal_scope.h"

namespace arbci::ui {

class EegView {
 public:
  // `photodiode`: the photodiode channel's name ("" for none); `impedance`: the source's report
  // ("" when it has none).
  void draw(const bci::SignalScope& scope, const std::string& photodiode,
            const std::string& impedance);
  // The time base as the control would set it: the first it offers at or above `seconds`.
  void setTimeBase(double seconds);

 private:
  void drawControls();
  void drawQualityLegend(const bci::SignalScope& scope, const std::string& impedance);
  void drawTraces(const bci::SignalScope& scope);
  void drawQualityTable(const bci::SignalScope& scope);
  int scale_ = 2;      // in the scale list: +/-50 uV a row
  int time_base_ = 1;  // 5 s
  bool filtered_ = true;
  std::string photodiode_;
  std::vector<ImVec2> points_;  // reused every frame
  std::vector<float> samples_;
};

}  // namespace arbci::ui
