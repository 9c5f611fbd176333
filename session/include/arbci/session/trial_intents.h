// What the simulated subject intends in each trial of a session: the session file's list, then
// random choices for the seed. A real subject's intentions come from the experimenter's protocol;
// these say which selections count as right.
#pragma once

#include <vector>

#include "arbci/session/session_config.h"

namespace arbci::session {

// One per trial (`paradigm.trials`): an object to a free cell, as a subject would, supposing the
// earlier trials went as intended.
std::vector<TrialIntent> intendedTrials(const SessionConfig& config);

}  // namespace arbci::session
