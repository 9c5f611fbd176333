// The subject's view on an OpenXR headset (hmd.output "openxr"): an instance, the headset and a
// session on the application's OpenGL context (headless EGL through XR_MNDX_egl_enable, a GLX
// window through XR_KHR_opengl_enable), one swapchain per eye. Each frame waits for the
// runtime's pacing (xrWaitFrame), copies the HMD stage's stereo framebuffer into the eyes' images
// and submits them as one projection layer; the frame's predicted display time comes back on the
// host clock, so flash onsets are stamped when the headset shows them.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "arbci/render/gl_context.h"

namespace arbci::render {

// An OpenXR call failed, or the runtime lost or ended the session: the message names the
// runtime (where one answered), the call and its result ("XR_ERROR_RUNTIME_UNAVAILABLE (-51)").
class OpenXrError : public std::runtime_error {
 public:
  OpenXrError(const std::string& message, int result)
      : std::runtime_error(message), result_(result) {}
  int result() const { return result_; }

 private:
  int result_;
};

// "XR_ERROR_RUNTIME_UNAVAILABLE (-51)"; unknown values as "XrResult -1234".
std::string xrResultText(int result);

// The headset's pose in the runtime's LOCAL space at a frame's display time.
struct HeadPose {
  std::array<double, 3> position{};     // metres
  std::array<double, 4> orientation{};  // unit quaternion x, y, z, w
};

// One frame handed to the runtime.
struct XrFrameTiming {
  // The runtime showed the layer (false: it asked for no rendering this frame, e.g. the headset
  // is not worn or the session is not visible; the frame was ended without a layer).
  bool rendered = false;
  // Its predicted display time on the host clock (a frame handed over after that time: the first
  // refresh after the handover).
  double display_host_s = 0.0;
  double submitted_host_s = 0.0;  // when xrEndFrame returned (the window path's swap stamp)
  double period_s = 0.0;          // the runtime's predicted display period
  std::optional<HeadPose> head;   // where the runtime tracks the headset
};

class OpenXrDisplay {
 public:
  // Opens the OpenXR `loader` (a shared library, opened now: nothing else needs it), the runtime
  // and the headset on `context` (current) with eyes of `eye` pixels each, and waits up to
  // `ready_s` for the runtime to make the session ready. Throws OpenXrError saying what is
  // missing: no loader or runtime, no headset, no OpenGL binding, a session never ready.
  OpenXrDisplay(GlContext& context, Size eye, double ready_s = 5.0,
                const std::string& loader = "libopenxr_loader.so.1");
  ~OpenXrDisplay();
  OpenXrDisplay(const OpenXrDisplay&) = delete;
  OpenXrDisplay& operator=(const OpenXrDisplay&) = delete;

  // "Monado(XRT) ... 21.0.0": the runtime's name and version as it reports them.
  const std::string& runtime() const;
  // The headset's name as the runtime reports it.
  const std::string& system() const;
  Size eyeSize() const;
  // The runtime's display period (s), measured on empty frames when the session began.
  double periodS() const;

  // Waits for the runtime's next frame and submits `texture` (both eyes side by side, `size`).
  // Throws OpenXrError when the runtime is lost or ends the session.
  XrFrameTiming submit(unsigned int texture, Size size);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

// Copies the left and right halves of `texture` (`size`: both eyes side by side) into `left` and
// `right` (textures of `eye` pixels), scaled where the sizes differ. The context must be current.
void copyEyes(unsigned int texture, Size size, unsigned int left, unsigned int right, Size eye);

}  // namespace arbci::render
