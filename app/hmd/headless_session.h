// A headless session run to its end on an EGL context: opened, stepped, its frames presented by
// the session itself or, with hmd.output "openxr", by the headset's runtime (then in real time,
// the runtime pacing the frames; a runtime that cannot be opened fails the pre-flight).
#pragma once

#include <functional>

#include "arbci/render/gl_context.h"
#include "hmd/open_session.h"

namespace arbci::app {

// `opened` runs once the session exists (before its first step). Throws as openSession does.
OpenedSession runHeadlessSession(const session::SessionConfig& config,
                                 session::SessionOptions options, render::GlContext& context,
                                 const std::function<void()>& opened = {});

}  // namespace arbci::app
