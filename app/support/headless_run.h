// A session run to its end without a window: a status line on stderr, rewritten in place at every
// phase change and every ten seconds of frames; Ctrl+C (support/interrupt.h) aborts it, and the
// summary is still saved.
#pragma once

#include <functional>

#include "arbci/session/session.h"

namespace arbci::app {

// `presented`, when given, runs after each step: the display that presents the frame (an HMD
// runtime) tells the session when.
void runHeadless(session::Session& session, const std::function<void()>& presented = {});

}  // namespace arbci::app
