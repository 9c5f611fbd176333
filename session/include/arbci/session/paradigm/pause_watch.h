// What pauses the paradigm by itself, and resumes it: an EEG source in fault (flashing without EEG
// would decide on nothing) and objects out of view (their flashes are withheld: never a flash for
// an object whose pose is stale). Each says why, in the log, to the experimenter and as the
// panel's reason; without an experimenter a selection whose every flash stays withheld ends the
// run with the reason instead of waiting.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "arbci/bci/paradigm.h"
#include "arbci/session/cycle.h"
#include "arbci/session/session_config.h"
#include "arbci/session/stage.h"

namespace arbci::session {

// Why the paradigm last stopped (a calibration selection interrupted there is retaken with this
// reason), and the panel's reason now ("" when all goes as planned).
struct StopReasons {
  std::string stopped_because;
  std::string status;
};

// An EEG source fault pauses the paradigm where it needs EEG; once the source has delivered for
// 2 s again it resumes (epochs touching the gap are discarded by the P300 stage).
class EegFaultWatch {
 public:
  void watch(const Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons,
             const StageServices& s);

 private:
  bool paused_ = false;
  double ok_since_ = -1.0;
};

// Objects out of view: their flashes are withheld (the recording says when tracking is lost and
// regained); a calibration flash withheld pauses the selection until every object has been in
// view for a second, and it is then retaken; a selection whose every flash is withheld for
// paradigm.no_view_pause_s pauses the session (or, with nobody at the window, ends it).
// Every marker lost at once, the reference with the objects, is a stall of the machine (the
// process or the cameras held up), not of tracking: the flashes are held and go on with the
// sequence once the markers are back, the selection not retaken; stalls that keep coming are
// named (the PC is too slow, with the figures) and asked about once (the run paused; resumed, it
// goes on without asking again). gates.max_retakes is a hard cap: past it no selection is
// retaken, an object out of view has its calibration flashes withheld and the selection goes on.
class ViewWatch {
 public:
  ViewWatch(const WorldSettings& world, double no_view_pause_s, bool experimenter, int max_retakes)
      : world_(world),
        no_view_pause_s_(no_view_pause_s),
        experimenter_(experimenter),
        max_retakes_(max_retakes) {}

  // This frame's stimulus without the flashes of offered objects (slots: world.objects by code)
  // whose pose is stale at the cycle's time.
  void withholdStale(Cycle& cycle, const std::vector<size_t>& slots, bci::Phase phase,
                     bci::FrameStimulus& stimulus);
  // A flash the paradigm scheduled was withheld (its object `object_id`), or one was shown.
  void flashWithheld(int object_id, int selection, Cycle& cycle, bci::Paradigm& paradigm,
                     StopReasons& reasons, const StageServices& s);
  void flashShown() { withheld_since_ = -1.0; }
  // What a pause it made waits for before it resumes by itself ("" when none does).
  std::string waitingFor() const;
  // The pause now is its own for a withheld calibration flash: resumed, the selection is
  // retaken (it lacks that flash).
  bool retakeOnResume() const { return paused_ && retake_on_resume_; }
  // summary.json's "stalls" (count, longest, the PC-too-slow warnings).
  void report(nlohmann::json& summary) const;

  // Stalls this many times within kSlowWindowS: the PC is too slow for the session.
  static constexpr int kSlowStalls = 5;
  static constexpr double kSlowWindowS = 60.0;
  // The pause for view: resumed once the objects have been in view for a second; a selection
  // withheld too long paused (or the run ended).
  void watch(Cycle& cycle, bci::Paradigm& paradigm, size_t offered, StopReasons& reasons,
             const StageServices& s);

 private:
  void pause(const std::string& why, const std::string& status, double time,
             bci::Paradigm& paradigm, StopReasons& reasons);
  void hold(Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons, const StageServices& s);
  void endHold(Cycle& cycle, bci::Paradigm& paradigm, StopReasons& reasons, const StageServices& s);
  // "no object in view: the reference marker or objects (10, 40) lost for 10 s (...), CONTEXT"
  std::string lostReason(const std::string& context, size_t offered) const;

  WorldSettings world_;
  double no_view_pause_s_;
  bool experimenter_;
  int max_retakes_;
  std::set<int> stale_;    // offered objects whose pose is stale (marker ids)
  bool all_lost_ = false;  // the reference and every offered object stale together
  // Stalls: held now (since when), when each began, the longest, the warnings given.
  bool held_ = false;
  double held_at_ = 0.0, longest_stall_s_ = 0.0;
  std::vector<double> stalls_;
  int too_slow_told_ = 0;
  bool retakes_capped_ = false;
  bool retake_on_resume_ = false;
  bool asking_ = false;  // its pause asks the experimenter: no resuming by itself
  // Since when every flash of the selection has been withheld (-1: a flash was shown since).
  double withheld_since_ = -1.0;
  bool paused_ = false;
  double paused_at_ = -1.0, in_view_since_ = -1.0;
};

}  // namespace arbci::session
