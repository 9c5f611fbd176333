#include "arbci/session/paradigm/pause_watch.h"

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
  // A calibration flash withheld: the selection stops there, paused until every object is in
  // view again, and is then retaken (training needs whole selections).
  const std::string reason = "calibration selection " + std::to_string(selection) + ": object " +
                             std::to_string(object_id) +
                             "'s flash withheld (tracking lost); the selection is retaken once "
                             "every object has been in view for 1 s";
  pause("tracking lost: object " + std::to_string(object_id), reason, time, paradigm, reasons);
  s.log.write("paused", time, {{"reason", reason}});
  s.tell.say(time, Severity::Warning, "paused: " + reason);
}

void ViewWatch::watch(Cycle& cycle, bci::Paradigm& paradigm, size_t offered, StopReasons& reasons,
                      const StageServices& s) {
  using bci::Phase;
  const Phase phase = paradigm.phase();
  const double time = cycle.time_s;
  if (paused_) {
    if (phase != Phase::Paused) {
      paused_ = false;  // the experimenter resumed or ended it
      withheld_since_ = -1.0;
      return;
    }
    in_view_since_ = stale_.empty() ? (in_view_since_ < 0.0 ? time : in_view_since_) : -1.0;
    if (in_view_since_ >= 0.0 && time - in_view_since_ >= 1.0) {
      paradigm.resume();
      paused_ = false;
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
