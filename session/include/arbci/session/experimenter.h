// What the experimenter may do now, and why not: read from the last cycle's record (the
// paradigm's phase, the arm's state), so the panels can grey a button out with its reason and the
// session refuses (and logs) an action that cannot go.
#pragma once

#include <optional>
#include <string>

#include "arbci/session/cycle.h"

namespace arbci::session {

enum class Action {
  Start,
  Pause,
  Resume,
  Abort,
  EmergencyStop,
  ResetRobot,
  Home,
  OpenGripper,
  RetryStep,
  SkipTrial,
  EndSession,
};
const char* toString(Action action);  // as the log's "refused" lines name it

// The experimenter's action a request is, for its why-not; none for a panel's setting (the
// threshold, the reference, a model).
std::optional<Action> actionOf(const Request& request);

// "" when `action` can go now, else why not, from the last cycle's record (`last.ended`: the run
// has ended).
std::string whyNot(Action action, const CycleRecord& last);

// How a run ended, for the summary: "finished" (also a timing check done), "estop" or "fault"
// when it ends in an emergency stop or a robot fault, "aborted" otherwise.
std::string endKindOf(const std::string& reason, bci::Phase phase);

}  // namespace arbci::session
