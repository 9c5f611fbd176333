#include "hmd/hmd_stage.h"

#include <opencv2/imgproc.hpp>

#include "hmd/hmd_composition.h"

namespace arbci::app {

HmdSettings HmdSettings::of(const session::SessionConfig& config) {
  return {config.hmd.width,
          config.hmd.height,
          config.hmd.undistort,
          config.world.objects,
          config.world.grid,
          !config.eeg.photodiode_channel.empty() || !config.eeg.photodiode_marker.empty(),
          config.hmd.screenshots};
}

HmdStage::HmdStage(const HmdSettings& settings, const std::filesystem::path& folder,
                   render::GlContext& context, const session::CycleRecord& warm_up,
                   const session::StageServices& services)
    : settings_(settings),
      s_(services),
      grid_(gridLayoutOf(settings.grid)),
      context_(context),
      screenshots_(folder, settings.screenshots) {
  context_.makeCurrent();
  fbo_ = std::make_unique<render::Framebuffer>(render::Size{settings.width, settings.height});
  view_ = std::make_unique<render::HmdView>();
  view_->setUndistort(settings_.undistort);
  // Every kind of overlay once: highlights in each state, the grid with rows, columns and cells.
  bci::FrameStimulus all;
  all.grid_visible = true;
  all.phase = bci::Phase::CellFlashing;
  all.lit = {1, settings_.grid.rows + 1};
  all.cued_object = 1;
  all.selected_object = 2;
  all.selected_cell = std::make_pair(1, 1);
  draw(all, warm_up, 0.0);
  all.phase = bci::Phase::ObjectFlashing;
  draw(all, warm_up, 0.0);
  draw(bci::FrameStimulus{}, warm_up, 0.0);
}

bool HmdStage::draw(const bci::FrameStimulus& stimulus, const session::CycleRecord& record,
                    double now_s) {
  const auto& status = record.robot.status;
  HmdScene scene{settings_.objects,
                 record.tracking,
                 record.paradigm.slots,
                 status ? status->holding : -1,
                 grid_,
                 settings_.photodiode,
                 now_s,
                 {}};
  const cv::Mat& eye = record.tracking.left_image;
  if (const std::string text = restText(stimulus.phase); !text.empty() && !eye.empty())
    scene.rest = rest_.image(eye.size(), text);
  const render::HmdFrame frame = composeHmdFrame(stimulus, scene);
  // What this frame shows; unchanged, the framebuffer already holds it.
  const std::string signature = hmdFrameSignature(frame);
  if (signature == last_signature_) return false;
  view_->draw(frame, fbo_->id(), fbo_->size());
  last_signature_ = signature;
  return true;
}

void HmdStage::step(session::Cycle& cycle) {
  context_.makeCurrent();
  const bci::FrameStimulus& stimulus = cycle.record.paradigm.stimulus;
  for (const session::PhaseChange& change : cycle.record.paradigm.phase_changes)
    screenshots_.phaseEntered(change.phase, change.trial);
  session::DisplayPart& out = cycle.record.display;
  out.photodiode = settings_.photodiode;
  out.redrawn = draw(stimulus, cycle.record, cycle.time_s);
  if (settings_.photodiode && out.redrawn) {
    // What the patch really shows, read back from the frame (a diode would see the same).
    const int middle = render::HmdFrame::kPatchPx / 2;
    out.patch_lit = render::readGrey(fbo_->id(), fbo_->size(), middle, middle) > 127;
  }
  if (const auto path = screenshots_.take(stimulus)) screenshot(*path);
  reportImageFailures(cycle);
  if (context_.isHeadless()) context_.present();  // a window is presented by its owner
}

void HmdStage::stop(session::Cycle& cycle, const std::string&) {
  images_.flush();
  reportImageFailures(cycle);
}

// A screenshot that could not be written (a full disk) is said once, with the reason; the run
// goes on (the recording is what must not be lost, and its own writes end the run).
void HmdStage::reportImageFailures(session::Cycle& cycle) {
  const auto failure = images_.failure();
  if (!failure || *failure == reported_failure_) return;
  reported_failure_ = *failure;
  s_.log.write("screenshot_failed", cycle.time_s, {{"text", *failure}});
  s_.tell.say(cycle.time_s, session::Severity::Warning, "screenshot not written: " + *failure);
}

void HmdStage::report(nlohmann::json& summary) const {
  summary["screenshots"] = {{"kept", settings_.screenshots},
                            {"written", images_.written()},
                            {"failed", images_.failed()}};
  if (const auto failure = images_.failure()) summary["screenshots"]["failure"] = *failure;
}

void HmdStage::screenshot(const std::filesystem::path& path) {
  const render::RgbaImage image = render::readPixels(fbo_->id(), fbo_->size());
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  images_.write(path, bgr);
}

}  // namespace arbci::app
