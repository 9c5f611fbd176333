// A session as the application runs it: the simulated cameras registered, the HMD's render stage
// added in `context` (current while the session steps), and the session's own stages.
#pragma once

#include <memory>

#include "arbci/render/gl_context.h"
#include "arbci/session/session.h"

namespace arbci::app {

class HmdStage;

struct OpenedSession {
  std::unique_ptr<session::Session> session;
  HmdStage* hmd = nullptr;  // the HMD framebuffer, for the panels and screenshots
};

// Throws as session::Session does.
OpenedSession openSession(const session::SessionConfig& config,
                          const session::SessionOptions& options, render::GlContext& context);

}  // namespace arbci::app
