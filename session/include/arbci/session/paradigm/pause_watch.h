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
class ViewWatch {
 public:
  ViewWatch(const WorldSettings& world, double no_view_pause_s, bool experimenter)
      : world_(world), no_view_pause_s_(no_view_pause_s), experimenter_(experimenter) {}

  // This frame's stimulus without the flashes of offered objects (slots: world.objects by code)
  // whose pose is stale at the cycle's time.
  void withholdStale(Cycle& cycle, const std::vector<size_t>& slots, bci::Phase phase,
                     bci::FrameStimulus& stimulus);
  // A flash the paradigm scheduled was withheld (its object `object_id`), or one was shown.
  void flashWithheld(int object_id, int selection, Cycle& cycle, bci::Paradigm& paradigm,
                     StopReasons& reasons, const StageServices& s);
  void flashShown() { withheld_since_ = -1.0; }
  // The pause for view: resumed once the objects have been in view for a second; a selection
  // withheld too long paused (or the run ended).
  void watch(Cycle& cycle, bci::Paradigm& paradigm, size_t offered, StopReasons& reasons,
             const StageServices& s);

 private:
  void pause(const std::string& why, const std::string& status, double time,
             bci::Paradigm& paradigm, StopReasons& reasons);
  // "no object in view: the reference marker or objects (10, 40) lost for 10 s (...), CONTEXT"
  std::string lostReason(const std::string& context, size_t offered) const;

  WorldSettings world_;
  double no_view_pause_s_;
  bool experimenter_;
  std::set<int> stale_;  // offered objects whose pose is stale (marker ids)
  // Since when every flash of the selection has been withheld (-1: a flash was shown since).
  double withheld_since_ = -1.0;
  bool paused_ = false;
  double paused_at_ = -1.0, in_view_since_ = -1.0;
};

}  // namespace arbci::session
