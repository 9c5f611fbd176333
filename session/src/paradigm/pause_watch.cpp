#include "arbci/session/paradigm/pause_watch.h"

#include <algorithm>
#include <cstdio>

namespace arbci::session {

void EegFaultWatch::watch(const Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons,
                          const StageServices& s) {
  using bci::Phase;
  const Phase phase = paradigm.phase();
  const std::string& fault = cycle.record.eeg.fault;
  const double time = cycle.time_s;
  if (!fault.empty()) {
    ok_since_ = -1.0;
    // Flashing (or cueing, or showing feedback) without EEG would decide on nothing: the
    // paradigm waits. The robot's own steps need no EEG and go on.
    const bool needs_eeg = phase == Phase::CalibrationCue || phase == Phase::CalibrationFlashing ||
                           phase == Phase::CalibrationFeedback || phase == Phase::ObjectFlashing ||
                           phase == Phase::CellFlashing || phase == Phase::ObjectSelected ||
                           phase == Phase::CellSelected;
    if (!paused_ && needs_eeg) {
      reasons.stopped_because = "EEG source fault";
      paradigm.pause();
      paused_ = true;
      reasons.status = "paused: " + fault;
      s.log.write("paused", time, {{"reason", "EEG source fault"}, {"fault", fault}});
      s.tell.say(time, Severity::Error,
                 "paused: " + fault + " (resumes 2 s after the EEG is back)");
    }
    return;
  }
  if (!paused_) return;
  if (phase != Phase::Paused) {
    paused_ = false;  // the experimenter resumed or ended it
    return;
  }
  if (ok_since_ < 0.0) ok_since_ = time;
  // Two seconds of signal again, then the sequence starts over (epochs touching the gap, and a
  // second before their window, are discarded).
  if (time - ok_since_ >= 2.0) {
    paradigm.resume();
    paused_ = false;
    reasons.status.clear();
    s.log.write("resumed", time, {{"reason", "EEG source delivering again"}});
    s.tell.say(time, Severity::Info, "resumed: the EEG source delivers again");
  }
}

void ViewWatch::withholdStale(Cycle& cycle, const std::vector<size_t>& slots, bci::Phase phase,
                              bci::FrameStimulus& stimulus) {
  const TrackingPart& tracking = cycle.record.tracking;
  const bool objects = stimulus.phase == bci::Phase::ObjectFlashing ||
                       stimulus.phase == bci::Phase::CalibrationFlashing;
  std::set<int> stale;
  for (size_t k = 0; k < slots.size(); ++k) {
    const int id = world_.objects[slots[k]].id;
    if (!tracking.fresh(id, cycle.time_s)) stale.insert(id);
    if (objects && stale.count(id)) stimulus.lit.erase(static_cast<int>(k) + 1);
  }
  all_lost_ = !stale.empty() && stale.size() == slots.size() &&
              !tracking.fresh(world_.reference_id, cycle.time_s);
  // The recording says when an offered object's tracking is lost and regained (once started).
  if (phase != bci::Phase::Setup) {
    for (int id : stale)
      if (!stale_.count(id))
        cycle.annotate(cycle.eeg_sample, "Tracking lost object " + std::to_string(id));
    for (int id : stale_)
      if (!stale.count(id))
        cycle.annotate(cycle.eeg_sample, "Tracking regained object " + std::to_string(id));
  }
  stale_ = std::move(stale);
}

void ViewWatch::flashWithheld(int object_id, int selection, Cycle& cycle, bci::Paradigm& paradigm,
                              StopReasons& reasons, const StageServices& s) {
  const double time = cycle.time_s;
  if (withheld_since_ < 0.0) withheld_since_ = time;
  if (paradigm.phase() != bci::Phase::CalibrationFlashing) return;
  if (all_lost_) {
    hold(cycle, paradigm, reasons, s);
    return;
  }
  if (paradigm.calibrationRetakes() >= max_retakes_) {
    // A hard cap: the run never loops on retakes. From here a selection goes on with the flashes
    // of an object out of view withheld (training takes the flashes there are), said once.
    if (!retakes_capped_) {
      retakes_capped_ = true;
      std::string reason =
          "calibration selections retaken " + std::to_string(paradigm.calibrationRetakes()) +
          " times (gates.max_retakes): no more retakes; an object out of view "
          "(now " +
          std::to_string(object_id) + ") has its flashes withheld and the selection goes on";
      s.log.write("retakes_capped", time, {{"reason", reason}});
      s.tell.say(time, Severity::Warning, reason);
      cycle.annotate(cycle.eeg_sample, "Retakes capped: " + reason);
    }
    return;
  }
  // A calibration flash withheld: the selection stops there, paused until every object has been
  // in view for a second, and is then retaken (it lacks that object's flash).
  const std::string reason = "calibration selection " + std::to_string(selection) + ": object " +
                             std::to_string(object_id) +
                             "'s flash withheld (tracking lost); the selection is retaken once "
                             "every object has been in view for 1 s";
  pause("tracking lost: object " + std::to_string(object_id), reason, time, paradigm, reasons);
  retake_on_resume_ = true;
  s.log.write("paused", time, {{"reason", reason}});
  s.tell.say(time, Severity::Warning, "paused: " + reason);
}

void ViewWatch::watch(Cycle& cycle, bci::Paradigm& paradigm, size_t offered, StopReasons& reasons,
                      const StageServices& s) {
  using bci::Phase;
  const Phase phase = paradigm.phase();
  const double time = cycle.time_s;
  if (held_) {
    if (phase != Phase::Paused) {
      held_ = false;  // the experimenter resumed or ended it
      return;
    }
    // The markers back: the flashes go on (no second's wait: nothing moved).
    if (!all_lost_ && stale_.empty()) endHold(cycle, paradigm, reasons, s);
    return;
  }
  if (paused_) {
    if (phase != Phase::Paused) {
      paused_ = retake_on_resume_ = asking_ = false;  // the experimenter resumed or ended it
      withheld_since_ = -1.0;
      return;
    }
    // A question (the PC too slow) waits for the experimenter's answer.
    if (asking_) return;
    in_view_since_ = stale_.empty() ? (in_view_since_ < 0.0 ? time : in_view_since_) : -1.0;
    if (in_view_since_ >= 0.0 && time - in_view_since_ >= 1.0) {
      paradigm.resume(retake_on_resume_);
      paused_ = retake_on_resume_ = false;
      withheld_since_ = -1.0;
      reasons.status.clear();
      s.log.write("resumed", time, {{"reason", "the objects are in view again"}});
      s.tell.say(time, Severity::Info, "resumed: the objects are in view again");
    } else if (!experimenter_ && time - paused_at_ >= no_view_pause_s_) {
      // Nobody can bring them back into view: the run ends, saying why.
      const std::string reason = lostReason("during calibration", offered);
      s.log.write("paused", time, {{"reason", reason}});
      cycle.end(reason, "aborted");
    }
    return;
  }
  const bool flashing = phase == Phase::ObjectFlashing || phase == Phase::CalibrationFlashing;
  if (!flashing) withheld_since_ = -1.0;
  if (withheld_since_ < 0.0 || time - withheld_since_ < no_view_pause_s_) return;
  const std::string reason = lostReason("every flash withheld", offered);
  s.log.write("paused", time, {{"reason", reason}});
  if (!experimenter_) {
    // Nobody can bring them back into view: the run ends, saying why.
    cycle.end(reason, "aborted");
    return;
  }
  pause("no object in view", reason + "; resumes once they are seen again", time, paradigm,
        reasons);
  s.tell.say(time, Severity::Error, "paused: " + reason);
}

void ViewWatch::hold(Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons,
                     const StageServices& s) {
  const double time = cycle.time_s;
  held_ = true;
  held_at_ = time;
  stalls_.push_back(time);
  reasons.stopped_because = "stall";
  reasons.status =
      "held: every marker vanished at once, the reference too (the machine stalled, not "
      "tracking); the flashes go on when the markers are back";
  paradigm.pause();
  s.log.write("stall", time, {{"what", "every marker lost at once"}, {"held", true}});
  cycle.annotate(cycle.eeg_sample, "Stall: every marker lost at once; flashes held");
}

void ViewWatch::endHold(Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons,
                        const StageServices& s) {
  const double time = cycle.time_s, seconds = time - held_at_;
  held_ = false;
  longest_stall_s_ = std::max(longest_stall_s_, seconds);
  withheld_since_ = -1.0;
  reasons.status.clear();
  paradigm.resumeHeld();
  s.log.write("stall_ended", time, {{"seconds", seconds}});
  cycle.annotate(cycle.eeg_sample, "Stall ended: flashes go on");
  // Stalls that keep coming: the PC cannot hold the session's pace. Asked once (the run paused);
  // the answer lasts for the run: resumed, every later stall is held and annotated unasked.
  int recent = 0;
  for (double at : stalls_) recent += at >= time - kSlowWindowS;
  if (recent < kSlowStalls || too_slow_told_ > 0) return;
  ++too_slow_told_;
  char text[400];
  std::snprintf(text, sizeof text,
                "the PC is too slow for this session: %d stalls in the last %.0f s (the longest "
                "%.0f ms) froze the cameras and the screen; close other programs, or run the "
                "EEG panel and the mirror window less",
                recent, kSlowWindowS, 1000.0 * longest_stall_s_);
  s.log.write("pc_too_slow", time,
              {{"stalls", recent}, {"window_s", kSlowWindowS}, {"longest_s", longest_stall_s_}});
  if (!experimenter_) {
    s.tell.say(time, Severity::Error, std::string(text) + " (each stall is held and annotated)");
    return;
  }
  const std::string question =
      std::string(text) +
      ". Resume: carry on, each later stall held and annotated without asking again; Abort: end "
      "the run here (what was recorded is kept)";
  pause("the PC is too slow", question, time, paradigm, reasons);
  asking_ = true;
  s.tell.say(time, Severity::Error, "paused: " + question);
}

std::string ViewWatch::waitingFor() const {
  if (held_) return "the markers to come back after the stall";
  if (!paused_ || !retake_on_resume_) return "";
  std::string lost;
  for (int id : stale_) lost += (lost.empty() ? "" : ", ") + std::to_string(id);
  return "every object in view for 1 s" + (lost.empty() ? "" : " (not seen: " + lost + ")");
}

void ViewWatch::report(nlohmann::json& summary) const {
  summary["stalls"] = {{"count", stalls_.size()},
                       {"longest_s", longest_stall_s_},
                       {"pc_too_slow_warnings", too_slow_told_}};
  summary["retakes_capped"] = retakes_capped_;
}

void ViewWatch::pause(const std::string& why, const std::string& status, double time,
                      bci::Paradigm& paradigm, StopReasons& reasons) {
  reasons.stopped_because = why;
  paradigm.pause();
  paused_ = true;
  paused_at_ = time;
  in_view_since_ = -1.0;
  reasons.status = "paused: " + status;
}

std::string ViewWatch::lostReason(const std::string& context, size_t offered) const {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", no_view_pause_s_);
  std::string lost;
  for (int id : stale_) lost += (lost.empty() ? "" : ", ") + std::to_string(id);
  return std::string(stale_.size() >= offered ? "no object in view" : "tracking lost") +
         ": the reference marker or objects (" + lost + ") lost for " + seconds +
         " s (paradigm.no_view_pause_s), " + context;
}

}  // namespace arbci::session
