#include "support/headless_run.h"

#include <iostream>

#include "arbci/session/record_text.h"
#include "support/interrupt.h"
#include "support/status_line.h"

namespace arbci::app {

namespace {
std::string statusLine(const session::Session& session) {
  return session::statusLine(session.last(), session.config(),
                             session.timing().totalPercentiles().p50);
}
}  // namespace

void runHeadless(session::Session& session, const std::function<void()>& presented) {
  auto show = [&session] {
    std::cerr << "\r" << statusLine(session) << "      " << std::flush;
    setStatusLineOpen(true);
  };
  while (session.step()) {
    if (presented) presented();
    if (!session.last().paradigm.phase_changes.empty() || session.frame() % 600 == 0) show();
    if (interruptRequested()) session.request(session::AbortRequest{});
  }
  // A session that did not finish says why (the last reason the paradigm gave: a fault, a failed
  // training), not only how it ended.
  std::cerr << "\r" << statusLine(session) << "\nsession ended: " << session.endReason();
  const std::string& why = session.last().paradigm.status;
  if (session.endReason() != "finished" && !why.empty()) std::cerr << " (" << why << ")";
  std::cerr << "\n";
  setStatusLineOpen(false);
}

}  // namespace arbci::app
