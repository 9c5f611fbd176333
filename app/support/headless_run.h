// A session run to its end without a window: a status line on stderr, rewritten in place at every
// phase change and every ten seconds of frames; Ctrl+C (support/interrupt.h) aborts it, and the
// summary is still saved.
#pragma once

#include "arbci/session/session.h"

namespace arbci::app {

void runHeadless(session::Session& session);

}  // namespace arbci::app
