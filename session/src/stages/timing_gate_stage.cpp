#include "arbci/session/stages/timing_gate_stage.h"

#include <algorithm>
#include <cstdio>

namespace arbci::session {

TimingLimits timingLimitsOf(double max_flash_ms, double min_gap_ms, double min_soa_ms,
                            double max_off_share, double max_late_share,
                            const bci::ParadigmSettings& p) {
  const double frame_ms = 1000.0 / p.display_hz;
  const double flash_ms = p.flashFrames() * frame_ms;
  const double gap_ms = (p.onsetFrames() - p.flashFrames()) * frame_ms;
  TimingLimits l;
  // Twice the flash: a flash that long is no longer the stimulus the classifier was trained on.
  l.max_flash_ms = max_flash_ms > 0.0 ? max_flash_ms : 2.0 * flash_ms;
  // Half the gap: the two flashes start to read as one.
  l.min_gap_ms = min_gap_ms > 0.0 ? min_gap_ms : 0.5 * gap_ms;
  // One frame's slip is the display's jitter; more is a flash shown early.
  l.min_soa_ms = min_soa_ms > 0.0 ? min_soa_ms : (p.onsetFrames() - 1) * frame_ms;
  l.max_off_share = max_off_share;
  l.max_late_share = max_late_share;
  return l;
}

TimingGateStage::TimingGateStage(const TimingGateSettings& settings, const StageServices& services)
    : settings_(settings), s_(services), policy_(settings.policy) {}

namespace {

bool flashingPhase(bci::Phase phase) {
  return phase == bci::Phase::CalibrationFlashing || phase == bci::Phase::ObjectFlashing ||
         phase == bci::Phase::CellFlashing;
}

}  // namespace

void TimingGateStage::followPause(Cycle& cycle) {
  const bci::Phase phase = cycle.previous.paradigm.phase;
  // The pause asked for: seen begun, then seen over. Only then do the limits count afresh (the
  // cycle after the request the paradigm has not paused yet: that is no resumption).
  if (pause_ == Pause::Asked && phase == bci::Phase::Paused) pause_ = Pause::Holding;
  if (pause_ != Pause::Holding || phase == bci::Phase::Paused) return;
  pause_ = Pause::None;
  off_ = flashes_ = 0;
  late_.clear();
  if (phase == bci::Phase::Aborted || phase == bci::Phase::Finished) return;
  // Asked once: the experimenter's Resume carries the run on annotated.
  setPolicy(cycle, "annotate",
            "the experimenter resumed a timing pause: the run goes on with every flash off "
            "limits annotated, without timing pauses");
}

void TimingGateStage::setPolicy(Cycle& cycle, const std::string& policy, const std::string& why) {
  if (policy == policy_) return;
  policy_ = policy;
  ++policy_changes_;
  s_.log.write("timing_policy", cycle.time_s, {{"policy", policy}, {"why", why}});
  s_.tell.say(cycle.time_s, Severity::Info, "timing: " + why);
}

void TimingGateStage::step(Cycle& cycle) {
  for (const TimingPolicyRequest* request : requestsOf<TimingPolicyRequest>(cycle.record.requests))
    setPolicy(cycle, request->policy, request->why);
  if (policy_ == "off") return;
  const Presentation& shown = cycle.record.presentation;
  followPause(cycle);
  const TimingLimits& l = settings_.limits;
  for (const Presentation::Ended& e : shown.ended) {
    const double d = ms(e.duration_samples);
    longest_flash_ms_ = std::max(longest_flash_ms_, d);
    if (d > l.max_flash_ms) {
      ++long_flashes_;
      offLimits(cycle, "flash lasted", d, l.max_flash_ms, e.onset_sample, selection_);
    }
    last_end_ = std::max(last_end_.value_or(e.onset_sample), e.onset_sample + e.duration_samples);
  }
  for (const Presentation::Onset& o : shown.onsets) {
    if (o.flash.selection != selection_) {
      selection_ = o.flash.selection;
      flashes_ = off_ = 0;
      last_onset_.reset();
    }
    ++flashes_;
    if (last_onset_) {
      const double soa = ms(o.sample - *last_onset_);
      shortest_soa_ms_ = std::min(shortest_soa_ms_.value_or(soa), soa);
      if (soa < l.min_soa_ms) {
        ++short_soas_;
        offLimits(cycle, "onset-to-onset", soa, l.min_soa_ms, o.sample, selection_);
      }
      // The dark gap since the last flash ended (when it ended before this one began).
      if (last_end_ && *last_end_ > *last_onset_ && *last_end_ <= o.sample) {
        const double gap = ms(o.sample - *last_end_);
        shortest_gap_ms_ = std::min(shortest_gap_ms_.value_or(gap), gap);
        if (gap < l.min_gap_ms) {
          ++short_gaps_;
          offLimits(cycle, "dark gap before it", gap, l.min_gap_ms, o.sample, selection_);
        }
      }
    }
    last_onset_ = o.sample;
  }
  // Late frames count while flashes are due (never before Start, in a pause or a cue): a slow
  // frame elsewhere times no stimulus.
  if (shown.shown && flashingPhase(cycle.previous.paradigm.phase)) {
    late_.push_back(shown.late);
    if (static_cast<int>(late_.size()) > kLateWindow) late_.pop_front();
  }
  pauseIfPastLimits(cycle);
}

void TimingGateStage::offLimits(Cycle& cycle, const char* what, double value_ms, double limit_ms,
                                std::int64_t onset_sample, int selection) {
  ++off_;
  const bool longer = std::string(what) == "flash lasted";
  char text[160];
  std::snprintf(text, sizeof text, "Timing off limits: %s %.1f ms (%s %.1f ms)", what, value_ms,
                longer ? "limit" : "at least", limit_ms);
  cycle.annotate(onset_sample, text);
  s_.log.write("timing_off_limits", cycle.time_s,
               {{"what", what},
                {"ms", value_ms},
                {"limit_ms", limit_ms},
                {"onset_sample", onset_sample},
                {"selection", selection}});
}

void TimingGateStage::pauseIfPastLimits(Cycle& cycle) {
  int late = 0;
  for (bool l : late_) late += l;
  const double late_share =
      late_.empty() ? 0.0 : static_cast<double>(late) / static_cast<double>(late_.size());
  if (static_cast<int>(late_.size()) >= kLateWindow)
    late_share_max_ = std::max(late_share_max_, late_share);
  const TimingLimits& l = settings_.limits;
  const double off_share = flashes_ > 0 ? static_cast<double>(off_) / flashes_ : 0.0;
  char why[240] = "";
  if (flashes_ >= kMinFlashes && off_share > l.max_off_share) {
    std::snprintf(why, sizeof why,
                  "timing: %d of the selection's %d flashes off the timing limits (more than "
                  "%.0f %%, gates.max_off_share); each is annotated in the recording",
                  off_, flashes_, 100.0 * l.max_off_share);
  } else if (static_cast<int>(late_.size()) >= kLateWindow && late_share > l.max_late_share) {
    std::snprintf(why, sizeof why,
                  "timing: %d of the last %d frames presented late (more than %.0f %%, "
                  "gates.max_late_share): is the PC busy?",
                  late, kLateWindow, 100.0 * l.max_late_share);
  }
  if (why[0] == '\0' || pause_ != Pause::None) return;
  if (!flashingPhase(cycle.previous.paradigm.phase)) return;
  const bool pausing = policy_ == "pause" && settings_.experimenter;
  s_.log.write("timing_limit", cycle.time_s, {{"text", why}, {"paused", pausing}});
  // Counted once per selection (or late stretch): the limits count afresh from here.
  off_ = flashes_ = 0;
  late_.clear();
  if (!pausing) {
    // Not paused, the same warning would come every few seconds: once a minute is enough.
    if (!told_at_ || cycle.time_s - *told_at_ >= kTellEveryS) {
      s_.tell.say(cycle.time_s, Severity::Warning,
                  std::string(why) + " (the run goes on; told at most once a minute)");
      told_at_ = cycle.time_s;
    }
    return;
  }
  ++pauses_;
  pause_ = Pause::Asked;
  const std::string question =
      std::string(why) +
      ". Resume: the run goes on with every flash off limits annotated (no more timing pauses "
      "this run); Abort: the run ends here (what was recorded is kept)";
  s_.tell.say(cycle.time_s, Severity::Error, "paused: " + question);
  cycle.post(PauseRequest{question});
}

void TimingGateStage::report(nlohmann::json& summary) const {
  nlohmann::json& g = summary["timing_gate"];
  g = {{"policy", settings_.policy},
       {"policy_at_end", policy_},
       {"policy_changes", policy_changes_},
       {"limits",
        {{"max_flash_ms", settings_.limits.max_flash_ms},
         {"min_gap_ms", settings_.limits.min_gap_ms},
         {"min_soa_ms", settings_.limits.min_soa_ms},
         {"max_off_share", settings_.limits.max_off_share},
         {"max_late_share", settings_.limits.max_late_share}}},
       {"long_flashes", long_flashes_},
       {"short_gaps", short_gaps_},
       {"short_soas", short_soas_},
       {"longest_flash_ms", longest_flash_ms_},
       {"late_share_max", late_share_max_},
       {"pauses", pauses_}};
  g["shortest_gap_ms"] = shortest_gap_ms_ ? nlohmann::json(*shortest_gap_ms_) : nlohmann::json();
  g["shortest_soa_ms"] = shortest_soa_ms_ ? nlohmann::json(*shortest_soa_ms_) : nlohmann::json();
  g["verdict"] = long_flashes_ + short_gaps_ + short_soas_ == 0 && pauses_ == 0
                     ? "within limits"
                     : "off limits (see the recording's Timing notes)";
}

}  // namespace arbci::session
