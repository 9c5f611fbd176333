// The HMD's render stage, the cycle's last: draws what this frame shows (the camera images, the
// highlights, the grid, the photodiode patch) into the HMD framebuffer, skipping a frame
// identical to the last; keeps the phases' screenshots; reads the photodiode patch back from the
// frame drawn, so the presentation stage stamps what the screen really showed.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "arbci/render/framebuffer.h"
#include "arbci/render/gl_context.h"
#include "arbci/render/hmd_view.h"
#include "arbci/session/session_config.h"
#include "arbci/session/stage.h"
#include "hmd/image_writer.h"
#include "hmd/phase_screenshots.h"
#include "hmd/rest_screen.h"

namespace arbci::app {

// What the HMD's stage needs of the session file, and nothing else.
struct HmdSettings {
  int width, height;  // both eyes side by side
  bool undistort;     // the camera images, before the overlays
  std::vector<session::WorldObjectSettings> objects;
  session::GridSettings grid;
  bool photodiode = false;  // the frame carries the photodiode patch
  std::string screenshots;  // hmd.screenshots
  static HmdSettings of(const session::SessionConfig& config);
};

class HmdStage final : public session::Stage {
 public:
  // Draws into `context` (made current each cycle). Draws every kind of overlay once over
  // `warm_up` (the tracked warm-up frames), so Mesa compiles its shader variants before the cycle
  // is timed.
  HmdStage(const HmdSettings& settings, const std::filesystem::path& folder,
           render::GlContext& context, const session::CycleRecord& warm_up,
           const session::StageServices& services);

  const char* name() const override { return "render"; }
  void step(session::Cycle& cycle) override;
  void stop(session::Cycle& cycle, const std::string& reason) override;
  void report(nlohmann::json& summary) const override;

  unsigned int texture() const { return fbo_->colorTexture(); }
  render::Size size() const { return fbo_->size(); }
  // Writes the HMD view as it is now (PNG, on a background thread).
  void screenshot(const std::filesystem::path& path);

 private:
  bool draw(const bci::FrameStimulus& stimulus, const session::CycleRecord& record, double now_s);
  void reportImageFailures(session::Cycle& cycle);

  HmdSettings settings_;
  session::StageServices s_;
  std::string reported_failure_;  // the screenshot failure last told
  render::GridLayout grid_;
  render::GlContext& context_;
  std::unique_ptr<render::Framebuffer> fbo_;
  std::unique_ptr<render::HmdView> view_;
  PhaseScreenshots screenshots_;
  RestScreen rest_;
  ImageWriter images_;
  // The last frame drawn: an identical frame is not drawn again (the framebuffer still holds it).
  std::string last_signature_;
};

}  // namespace arbci::app
