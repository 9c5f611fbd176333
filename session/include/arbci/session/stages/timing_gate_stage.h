// The flashes' timing as presented, against limits (gates.timing): a flash shown too long, a dark
// gap before a flash too short, an onset too soon after the last one. Every flash off a limit is
// noted in the recording at its onset (so in a BIDS export's events) and in the log; when too many
// of a selection's flashes are off limits, or too many of the last frames came late, the run
// pauses with the reason (gates.timing "pause", with an experimenter to resume it; a run without
// one carries on, its flashes annotated). It asks once: resumed, the run goes on annotated (so
// does a run whose pre-flight asked about the display and was told so). Late frames count only
// while flashes are due. The summary's "timing_gate" counts them all.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "arbci/bci/paradigm.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct TimingLimits {
  double max_flash_ms = 0.0, min_gap_ms = 0.0, min_soa_ms = 0.0;
  double max_off_share = 0.0, max_late_share = 0.0;
};

struct TimingGateSettings {
  std::string policy;   // gates.timing: "pause", "annotate" or "off"
  TimingLimits limits;  // derived from the paradigm where the session file says 0
  double eeg_rate_hz = 0.0;
  bool experimenter = false;
};

// gates.* over the paradigm: each limit the session file leaves at 0 from the configured flash,
// gap and SOA (see docs/settings.md).
TimingLimits timingLimitsOf(double max_flash_ms, double min_gap_ms, double min_soa_ms,
                            double max_off_share, double max_late_share,
                            const bci::ParadigmSettings& paradigm);

class TimingGateStage final : public Stage {
 public:
  TimingGateStage(const TimingGateSettings& settings, const StageServices& services);
  const char* name() const override { return "timing_gate"; }
  void step(Cycle& cycle) override;
  void report(nlohmann::json& summary) const override;

  // Selections with fewer flashes than this are not judged by their share off limits.
  static constexpr int kMinFlashes = 12;
  // The late frames' share is taken over this many presented frames.
  static constexpr int kLateWindow = 120;
  // A run that is not paused for timing is told of it at most this often.
  static constexpr double kTellEveryS = 60.0;

 private:
  void offLimits(Cycle& cycle, const char* what, double value_ms, double limit_ms,
                 std::int64_t onset_sample, int selection);
  void pauseIfPastLimits(Cycle& cycle);
  // A pause it asked for, followed until the experimenter resumes it (see the source).
  void followPause(Cycle& cycle);
  void setPolicy(Cycle& cycle, const std::string& policy, const std::string& why);
  double ms(std::int64_t samples) const { return 1000.0 * samples / settings_.eeg_rate_hz; }

  TimingGateSettings settings_;
  StageServices s_;
  // The current selection: its number, flashes, those off limits, the last onset.
  int selection_ = -1, flashes_ = 0, off_ = 0;
  std::optional<std::int64_t> last_onset_, last_end_;
  std::deque<bool> late_;  // the last frames presented while flashing: late or not
  // A pause it asked for: asked (not yet taken), holding (the run is paused), none.
  enum class Pause { None, Asked, Holding } pause_ = Pause::None;
  // gates.timing for the rest of the run: the session file's, until the experimenter answers
  // (the pre-flight's display question, a timing pause resumed): each cause is asked once.
  std::string policy_;
  int policy_changes_ = 0;
  std::optional<double> told_at_;
  // For the summary.
  int long_flashes_ = 0, short_gaps_ = 0, short_soas_ = 0, pauses_ = 0;
  double longest_flash_ms_ = 0.0;
  std::optional<double> shortest_gap_ms_, shortest_soa_ms_;
  double late_share_max_ = 0.0;
};

}  // namespace arbci::session
