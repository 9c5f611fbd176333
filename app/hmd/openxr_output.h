// hmd.output "openxr": the HMD stage's frames go to a headset through its OpenXR runtime. Opened
// before the session, so that a missing loader, runtime or headset is a pre-flight failure naming
// the cause; then, each cycle, the frame drawn is submitted at the runtime's pacing and the
// session stamps its flashes at the runtime's predicted display time. A runtime lost mid-run
// pauses the run with the reason (an experimenter decides), or ends it as a fault when nobody is
// at the window; the recording and the log keep everything up to then.
#pragma once

#include <memory>
#include <string>

#include "arbci/render/gl_context.h"
#include "arbci/render/openxr_display.h"
#include "arbci/session/session.h"

namespace arbci::app {

class OpenXrOutput {
 public:
  // Opens the runtime on `context` with the HMD's eyes (hmd.width / 2 by hmd.height).
  OpenXrOutput(const session::SessionConfig& config, render::GlContext& context);

  // The pre-flight's line when the runtime could not be opened ("hmd.output = openxr: ..."),
  // else "".
  const std::string& failure() const { return failure_; }
  bool open() const { return display_ != nullptr; }
  // "Monado(XRT) ... 21.0.0, headset: Simulated HMD" once open.
  std::string describe() const;

  // Submits the frame the last step drew and tells the session when it will be shown. Returns
  // false when there was nothing to submit to (never opened, or lost: then the session was told).
  bool present(session::Session& session, unsigned int texture, render::Size size,
               bool experimenter);

 private:
  std::unique_ptr<render::OpenXrDisplay> display_;
  std::string failure_;
  bool hidden_told_ = false;  // the runtime's "no rendering" was told (once until it renders again)
};

}  // namespace arbci::app
