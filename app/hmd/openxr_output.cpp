#include "hmd/openxr_output.h"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace arbci::app {

OpenXrOutput::OpenXrOutput(const session::SessionConfig& config, render::GlContext& context) {
  try {
    display_ = std::make_unique<render::OpenXrDisplay>(
        context, render::Size{config.hmd.width / 2, config.hmd.height});
  } catch (const render::OpenXrError& error) {
    failure_ = std::string("hmd.output = openxr: ") + error.what() +
               " (start the headset's runtime, or set hmd.output to window)";
    return;
  }
  // Flashes last whole frames of display_hz: a headset at another rate would show them
  // for other durations than configured, and every frame late.
  const double hz = 1.0 / display_->periodS();
  const double configured = config.displayHz();
  if (std::abs(hz - configured) > 0.05 * configured) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << "hmd.output = openxr: the headset (" << describe()
         << ") shows a frame every " << 1000.0 / hz << " ms (" << hz << " Hz) while display_hz is "
         << configured << ": set display_hz to " << hz << " (or the headset's rate in its runtime)";
    failure_ = line.str();
    display_.reset();
  }
}

std::string OpenXrOutput::describe() const {
  if (!display_) return "";
  return display_->runtime() + ", headset: " + display_->system();
}

bool OpenXrOutput::present(session::Session& session, unsigned int texture, render::Size size,
                           bool experimenter) {
  if (!display_) return false;
  try {
    const render::XrFrameTiming t = display_->submit(texture, size);
    session::RuntimeFrame frame{t.submitted_host_s, std::nullopt};
    if (t.head) {
      const auto& p = t.head->position;
      const auto& q = t.head->orientation;
      frame.head = std::array<double, 7>{p[0], p[1], p[2], q[0], q[1], q[2], q[3]};
    }
    if (t.rendered) {
      session.presented(t.display_host_s, frame);
      hidden_told_ = false;
      return true;
    }
    // The runtime asked for no rendering (the headset taken off, the session not visible): the
    // subject sees no flash, so the frame is not stamped and the run does not flash on unseen.
    if (!hidden_told_) {
      hidden_told_ = true;
      const std::string reason =
          "the headset shows nothing (its runtime asks for no frames: taken off, or another "
          "application in front)";
      std::cerr << "\n" << reason << "\n";
      if (experimenter)
        session.request(session::PauseRequest{reason});
      else
        session.endNow(reason);
    }
    return true;
  } catch (const render::OpenXrError& error) {
    const std::string reason =
        std::string("the HMD's runtime is lost: ") + error.what() + "; the headset shows nothing";
    display_.reset();
    std::cerr << "\n" << reason << "\n";
    if (experimenter)
      session.request(session::PauseRequest{reason});
    else
      session.endNow(reason);
    return false;
  }
}

}  // namespace arbci::app
