#include "hmd/headless_session.h"

#include <iostream>
#include <optional>

#include "arbci/bci/sample_clock.h"
#include "hmd/hmd_stage.h"
#include "hmd/openxr_output.h"
#include "support/headless_run.h"

namespace arbci::app {

OpenedSession runHeadlessSession(const session::SessionConfig& config,
                                 session::SessionOptions options, render::GlContext& context,
                                 const std::function<void()>& opened) {
  std::optional<OpenXrOutput> xr;
  if (config.hmd.output == "openxr") {
    if (options.clock != session::Clock::Mode::RealTime)
      std::cerr << "hmd.output is \"openxr\" (a headset): running in real time\n";
    options.clock = session::Clock::Mode::RealTime;
    xr.emplace(config, context);
    if (xr->open()) {
      options.presents_itself = false;
      std::cerr << "HMD: " << xr->describe() << "\n";
    } else {
      options.display_failures.push_back(xr->failure());
    }
  }
  OpenedSession session = openSession(config, options, context);
  if (opened) opened();
  runHeadless(*session.session, [&] {
    // A frame the headset did not take (none, or lost: the session was told) is stamped now.
    if (xr && !xr->present(*session.session, session.hmd->texture(), session.hmd->size(), false))
      session.session->presented(bci::hostSeconds());
  });
  return session;
}

}  // namespace arbci::app
