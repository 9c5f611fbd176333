#include "hmd/open_session.h"

#include "hmd/hmd_stage.h"

namespace arbci::app {

OpenedSession openSession(const session::SessionConfig& config,
                          const session::SessionOptions& options, render::GlContext& context) {
  context.makeCurrent();
  OpenedSession opened;
  opened.session = std::make_unique<session::Session>(
      config, options,
      [&](const session::StageServices& services, const session::CycleRecord& warm_up) {
        auto hmd = std::make_unique<HmdStage>(HmdSettings::of(config), options.folder, context,
                                              warm_up, services);
        opened.hmd = hmd.get();
        return hmd;
      });
  return opened;
}

}  // namespace arbci::app
