// The HMD's stage: draws what this frame shows (the camera images, the highlights, the grid, the
// photodiode patch) into the HMD framebuffer, skipping a frame identical to the last; keeps the
// phases' screenshots; and, once the frame is presented, stamps its flashes: each onset and
// measured duration on the EEG sample clock, the photodiode patch as the frame really showed it,
// late frames and a display that cannot hold its rate, logged and said.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "arbci/render/framebuffer.h"
#include "arbci/render/hmd_view.h"
#include "session/cycle_timing.h"
#include "session/eeg_stage.h"
#include "session/image_writer.h"
#include "session/paradigm_stage.h"
#include "session/phase_screenshots.h"
#include "session/robot_choreography.h"
#include "session/session_config.h"
#include "session/session_log.h"
#include "session/stage.h"
#include "session/stimulus_timing.h"
#include "session/vision_stage.h"

namespace arbci::app {

// What the HMD's stage needs of the session file, and nothing else.
struct HmdSettings {
  int width, height;  // both eyes side by side
  bool undistort;     // the camera images, before the overlays
  double display_hz;
  std::vector<WorldObjectSettings> objects;
  GridSettings grid;
  static HmdSettings of(const SessionConfig& config);
};

class HmdStage final : public Stage {
 public:
  struct Services {
    const VisionStage& vision;
    const ParadigmStage& paradigm;
    const RobotChoreography& robot;
    EegStage& eeg;
    StimulusTiming& timing;
    const CycleTiming& cycle_timing;
    SessionLog& log;
    std::ostream* progress = nullptr;
  };
  // Needs a current GL context. Draws every kind of overlay once, so Mesa compiles its shader
  // variants before the cycle is timed.
  HmdStage(const HmdSettings& settings, const std::filesystem::path& folder, Services services);

  const char* name() const override { return "render"; }
  void step(CycleContext& cycle) override;
  void stop(const CycleContext& cycle, const std::string& reason) override;

  // The frame the last step drew reached the screen at host instant `host_s` (session second 0
  // being `host_origin`).
  void presented(double host_s, double host_origin, std::int64_t frame);
  // When the last frame reached the screen (session seconds), once one has.
  std::optional<double> lastPresented() const { return last_presented_; }

  unsigned int texture() const { return fbo_->colorTexture(); }
  render::Size size() const { return fbo_->size(); }
  // Writes the HMD view as it is now (PNG, on a background thread).
  void screenshot(const std::filesystem::path& path);

 private:
  void draw(const bci::FrameStimulus& stimulus, double now_s);
  void warnIfDisplayTooSlow(double at);

  HmdSettings settings_;
  render::GridLayout grid_;
  Services s_;
  std::unique_ptr<render::Framebuffer> fbo_;
  std::unique_ptr<render::HmdView> view_;
  PhaseScreenshots screenshots_;
  ImageWriter images_;
  // The last frame drawn: an identical frame is not drawn again (the framebuffer still holds it).
  std::string last_signature_;
  bool redrawn_ = false;
  // The frame drawn and not yet presented: when it is due, what it lights, which codes it shows
  // for the first time.
  bool pending_ = false;
  double due_ = 0.0;
  std::set<int> lit_;
  std::vector<int> first_shown_;
  std::optional<ParadigmStage::FeedbackShown> feedback_;  // a selection shown for the first time
  std::optional<double> last_presented_;
  bool patch_lit_ = false;  // as last told to the EEG source
  bool warned_slow_display_ = false;
};

}  // namespace arbci::app
