// What the window keeps beyond one cycle's record, each in one place: the EEG's last seconds with
// each channel's grade, every cycle's compute time by stage, the HMD view's texture, and what the
// start screen's labels mean (where the run goes, what stops it). The window's owner feeds it each
// record after the cycle; the panels read it.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/signal_scope.h"
#include "arbci/core/run_labels.h"
#include "arbci/session/cycle.h"
#include "arbci/session/session_config.h"

namespace arbci::ui {

struct StageTiming {
  std::string stage;  // a stage's name, or "total"
  double p50_ms = 0, p90_ms = 0, p99_ms = 0, max_ms = 0, last_ms = 0;
};

// For the start screen: what stops a start with the labels ("" when nothing), and where the run
// will be written ("BIDS: sub-07/eeg, ..., run 2 (the next free)", or the folder).
struct RunTarget {
  std::string problem, target;
};
using DescribeRun = std::function<RunTarget(const core::RunLabels&)>;

class WindowState {
 public:
  // `describe_run`: the application's account of a run's labels (it knows the BIDS root and the
  // session folders); none: nothing to say.
  explicit WindowState(DescribeRun describe_run = {}) : describe_run_(std::move(describe_run)) {}

  // After each cycle: its EEG blocks and flash onsets into the scope (10 s, the EEG panel's
  // longest time base), its compute times into the history, and the labels' account when they
  // changed.
  void ingest(const session::CycleRecord& record, const session::SessionConfig& settings);

  // The last seconds of every channel with its grade; none before the first samples.
  const bci::SignalScope* eegScope() const { return scope_ ? &*scope_ : nullptr; }
  // Each stage's compute time over every cycle so far (refreshed twice a second), then "total".
  const std::vector<StageTiming>& timing() const { return timing_; }
  double cycleP50Ms() const;
  // The last ~300 cycles' compute times (ms), oldest first: the Session panel's plot.
  const std::vector<float>& recentCycles() const { return recent_; }
  const RunTarget& runTarget() const { return run_target_; }

  // The HMD framebuffer's colour texture (0: none) and its width over its height.
  unsigned int hmd_texture = 0;
  float hmd_aspect = 1.0f;

 private:
  void refreshTiming(const session::CycleRecord& record);
  DescribeRun describe_run_;
  std::optional<bci::SignalScope> scope_;
  std::map<std::string, std::vector<double>> stage_ms_;
  std::vector<double> total_ms_;
  std::vector<StageTiming> timing_;
  std::vector<float> recent_;
  std::optional<core::RunLabels> described_;
  RunTarget run_target_;
};

}  // namespace arbci::ui
