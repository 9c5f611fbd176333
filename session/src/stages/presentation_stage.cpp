#include "arbci/session/stages/presentation_stage.h"

#include <cstdio>

namespace arbci::session {

PresentationStage::PresentationStage(const PresentationSettings& settings,
                                     const StageServices& services)
    : settings_(settings), s_(services), timing_(settings.paradigm, settings.eeg_rate_hz) {}

void PresentationStage::step(Cycle& cycle) {
  const CycleRecord& drawn = cycle.previous;
  Presentation& out = cycle.record.presentation;
  out = Presentation{};
  // A new selection's SOA is measured among its own flashes.
  if (drawn.paradigm.selection_started) timing_.startSelection();
  // Time the session stood interrupted is not selection time (bit rates count the subject's).
  const bci::Phase phase = drawn.paradigm.phase;
  if (last_time_s_ && (phase == bci::Phase::Paused || phase == bci::Phase::EmergencyStop ||
                       phase == bci::Phase::RobotFault))
    timing_.interrupted(cycle.time_s - *last_time_s_);
  last_time_s_ = cycle.time_s;
  if (drawn.presented) {
    out.shown = true;
    out.host_s = drawn.presented->host_s;
    out.at_s = s_.clock.sessionOf(out.host_s);
    out.sample = drawn.presented->sample;
    out.frame = drawn.frame;
    std::vector<int> first_shown;
    for (const Flash& f : drawn.paradigm.first_shown) first_shown.push_back(f.code);
    const StimulusTiming::Frame shown = timing_.presented(drawn.due_s, out.at_s, out.sample,
                                                          drawn.paradigm.stimulus.lit, first_shown);
    // What the patch really showed, read back from the frame (a diode would see the same); an
    // unchanged frame shows what the last one did.
    bool patch_lit = patch_lit_;
    if (drawn.display.photodiode && drawn.display.redrawn && drawn.display.patch_lit)
      patch_lit = *drawn.display.patch_lit;
    if (drawn.display.photodiode && patch_lit != patch_lit_) {
      out.patch = patch_lit;
      patch_lit_ = patch_lit;
    }
    for (const StimulusTiming::Ended& e : shown.ended)
      out.ended.push_back({e.onset_sample, e.duration_samples});
    for (size_t i = 0; i < shown.onsets.size(); ++i)
      out.onsets.push_back({drawn.paradigm.first_shown[i], shown.onsets[i].sample});
    out.feedback = drawn.paradigm.feedback;
    out.late = shown.late;
    if (shown.late) {
      s_.log.write("late_frame", out.at_s,
                   {{"frame", drawn.frame},
                    {"due_s", drawn.due_s},
                    {"late_ms", 1000.0 * (out.at_s - drawn.due_s)},
                    {"stages", drawn.stage_ms}});
    }
    warnIfDisplayTooSlow(out.at_s);
  }
  out.selection_s = timing_.selectionSeconds();
  out.selection_interrupted_s = timing_.selectionInterruptedSeconds();
  out.median_frame_ms = timing_.medianFrameIntervalMs();
  out.late_frames = timing_.lateFrames();
  out.display_too_slow = timing_.displayTooSlow();
}

void PresentationStage::stop(Cycle& cycle, const std::string&) {
  step(cycle);
}

void PresentationStage::warnIfDisplayTooSlow(double at) {
  // Checked once a second or so (it takes a median of the last frame intervals).
  if (warned_slow_display_ || timing_.framesPresented() % 60 != 0 || !timing_.displayTooSlow())
    return;
  warned_slow_display_ = true;
  const double median = *timing_.medianFrameIntervalMs();
  s_.log.write("display_too_slow", at,
               {{"configured_hz", settings_.paradigm.display_hz},
                {"median_frame_ms", median},
                {"text",
                 "the display cannot hold display_hz: flashes are stamped as presented, "
                 "so the recorded SOA and durations are longer than configured"}});
  char text[200];
  std::snprintf(text, sizeof text,
                "the display shows a frame every %.1f ms, not every %.1f ms: flash onsets are "
                "stamped as presented; the SOA is longer than configured",
                median, 1000.0 / settings_.paradigm.display_hz);
  s_.tell.say(at, Severity::Warning, text);
}

void PresentationStage::report(nlohmann::json& summary) const {
  summary["timing"].update(timing_.summary());
}

}  // namespace arbci::session
