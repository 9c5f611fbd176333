#include "support/headless_run.h"

#include <iostream>

#include "support/interrupt.h"
#include "support/status_line.h"
#include "workstation/session_model.h"

namespace arbci::app {

void runHeadless(session::Session& session) {
  auto show = [&session] {
    std::cerr << "\r" << statusLine(session) << "      " << std::flush;
    setStatusLineOpen(true);
  };
  while (session.step()) {
    if (!session.last().paradigm.phase_changes.empty() || session.frame() % 600 == 0) show();
    if (interruptRequested()) session.request(session::AbortRequest{});
  }
  std::cerr << "\r" << statusLine(session) << "\nsession ended: " << session.endReason() << "\n";
  setStatusLineOpen(false);
}

}  // namespace arbci::app
