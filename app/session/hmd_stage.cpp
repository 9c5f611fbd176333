#include "session/hmd_stage.h"

#include <opencv2/imgproc.hpp>

#include "arbci/bci/clock_model.h"
#include "session/hmd_composition.h"

namespace arbci::app {

HmdSettings HmdSettings::of(const SessionConfig& config) {
  return {config.hmd_width,  config.hmd_height,    config.undistort,
          config.display_hz, config.world.objects, config.world.grid};
}

HmdStage::HmdStage(const HmdSettings& settings, const std::filesystem::path& folder,
                   Services services)
    : settings_(settings),
      grid_(gridLayoutOf(settings.grid)),
      s_(services),
      fbo_(std::make_unique<render::Framebuffer>(render::Size{settings.width, settings.height})),
      view_(std::make_unique<render::HmdView>()),
      screenshots_(folder) {
  view_->setUndistort(settings_.undistort);
  // Every kind of overlay once: highlights in each state, the grid with rows, columns and cells.
  bci::FrameStimulus all;
  all.grid_visible = true;
  all.phase = bci::Phase::CellFlashing;
  all.lit = {1, settings_.grid.rows + 1};
  all.cued_object = 1;
  all.selected_object = 2;
  all.selected_cell = std::make_pair(1, 1);
  draw(all, 0.0);
  all.phase = bci::Phase::ObjectFlashing;
  draw(all, 0.0);
  draw(bci::FrameStimulus{}, 0.0);
}

void HmdStage::draw(const bci::FrameStimulus& stimulus, double now_s) {
  const auto& status = s_.robot.status();
  const HmdScene scene{
      settings_.objects,      s_.vision, s_.paradigm.slots(), status ? status->holding : -1, grid_,
      s_.eeg.hasPhotodiode(), now_s};
  const render::HmdFrame frame = composeHmdFrame(stimulus, scene);
  // What this frame shows; unchanged, the framebuffer already holds it.
  const std::string signature = hmdFrameSignature(frame);
  redrawn_ = signature != last_signature_;
  if (redrawn_) {
    view_->draw(frame, fbo_->id(), fbo_->size());
    last_signature_ = signature;
  }
}

void HmdStage::step(CycleContext& cycle) {
  const bci::FrameStimulus& stimulus = s_.paradigm.stimulus();
  for (const ParadigmStage::PhaseChange& change : s_.paradigm.phaseChanges())
    screenshots_.phaseEntered(change.phase, change.trial);
  draw(stimulus, cycle.time_s);
  if (const auto path = screenshots_.take(stimulus)) screenshot(*path);
  pending_ = true;
  due_ = cycle.due_s;
  lit_ = stimulus.lit;
  first_shown_ = s_.paradigm.firstShown();
  feedback_ = s_.paradigm.feedbackShown();
}

void HmdStage::stop(const CycleContext&, const std::string&) {
  images_.flush();
}

void HmdStage::screenshot(const std::filesystem::path& path) {
  const render::RgbaImage image = render::readPixels(fbo_->id(), fbo_->size());
  cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  images_.write(path, bgr);
}

void HmdStage::presented(double host_s, double host_origin, std::int64_t frame) {
  if (!pending_) return;
  pending_ = false;
  const double at = host_s - host_origin;
  const std::int64_t sample = s_.eeg.sampleAt(host_s);
  // What the patch really shows, read back from the frame (a diode would see the same); an
  // unchanged frame shows what the last one did.
  bool patch_lit = patch_lit_;
  if (s_.eeg.hasPhotodiode() && redrawn_) {
    const int middle = render::HmdFrame::kPatchPx / 2;
    patch_lit = render::readGrey(fbo_->id(), fbo_->size(), middle, middle) > 127;
  }
  const StimulusTiming::Frame shown = s_.timing.presented(due_, at, sample, lit_, first_shown_);
  if (s_.eeg.hasPhotodiode() && patch_lit != patch_lit_) {
    s_.eeg.displayed(host_s, patch_lit);
    patch_lit_ = patch_lit;
  }
  for (const StimulusTiming::Ended& ended : shown.ended)
    s_.eeg.flashEnded(ended.onset_sample, ended.duration_samples);
  for (const StimulusTiming::Onset& onset : shown.onsets)
    s_.eeg.flash(onset.code, onset.sample, host_s);
  if (feedback_) s_.eeg.feedback(feedback_->codes, feedback_->objects, feedback_->error, sample);
  if (shown.late) {
    s_.log.write("late_frame", at,
                 {{"frame", frame},
                  {"due_s", due_},
                  {"late_ms", 1000.0 * (at - due_)},
                  {"stages", s_.cycle_timing.lastCycle()}});
  }
  last_presented_ = at;
  warnIfDisplayTooSlow(at);
}

void HmdStage::warnIfDisplayTooSlow(double at) {
  // Checked once a second or so (it takes a median of the last frame intervals).
  if (warned_slow_display_ || s_.timing.framesPresented() % 60 != 0 || !s_.timing.displayTooSlow())
    return;
  warned_slow_display_ = true;
  const double median = *s_.timing.medianFrameIntervalMs();
  s_.log.write("display_too_slow", at,
               {{"configured_hz", settings_.display_hz},
                {"median_frame_ms", median},
                {"text",
                 "the display cannot hold display_hz: flashes are stamped as presented, "
                 "so the recorded SOA and durations are longer than configured"}});
  if (s_.progress)
    *s_.progress << "\nwarning: the display shows a frame every " << median << " ms, not every "
                 << 1000.0 / settings_.display_hz
                 << " ms: flash onsets are stamped as presented; the SOA is longer than "
                    "configured\n";
}

}  // namespace arbci::app
