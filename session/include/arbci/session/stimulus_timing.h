// What the screen really showed, and when: each presented frame's time against its due time
// (a frame presented more than one period late is a late frame), each flash's onset (the first
// frame that shows it) and measured duration (to the first frame that no longer does), both on
// the EEG sample clock, the measured SOA, and whether the display holds its nominal rate. The
// summary's timing block and the bit rate are computed from these, never from the settings.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/bci/paradigm.h"

namespace arbci::session {

class StimulusTiming {
 public:
  StimulusTiming(const bci::ParadigmSettings& paradigm, double eeg_rate_hz);

  struct Onset {
    int code = 0;
    std::int64_t sample = 0;
  };
  struct Ended {
    std::int64_t onset_sample = 0;
    int duration_samples = 0;
  };
  struct Frame {
    std::vector<Onset> onsets;  // flashes whose first frame this is
    std::vector<Ended> ended;   // flashes this frame no longer shows
    bool late = false;
    bool patch_lit = false;  // the photodiode patch: lit while any stimulus is
  };
  // A frame due at `due_s` was presented at `presented_s` (session seconds), the first EEG sample
  // at or after it being `sample`; it shows `lit`, of which `first_shown` for the first time.
  Frame presented(double due_s, double presented_s, std::int64_t sample, const std::set<int>& lit,
                  const std::vector<int>& first_shown);
  // A new selection starts (its SOA is measured among its own flashes).
  void startSelection();
  // The current selection's duration from its flash onsets: first onset to last, plus one SOA,
  // less the time it was interrupted (a pause, an E-STOP, a robot fault) once its flashes began.
  double selectionSeconds() const;
  // That interrupted time, counted by interrupted() since startSelection().
  double selectionInterruptedSeconds() const { return selection_interrupted_s_; }
  // `seconds` of the current selection passed with the session interrupted.
  void interrupted(double seconds);

  std::int64_t lateFrames() const { return late_frames_; }
  std::int64_t framesPresented() const { return frames_; }
  // Once 60 frames were presented: the median frame interval, and whether it exceeds 1.5 nominal
  // periods (the display cannot hold its rate).
  std::optional<double> medianFrameIntervalMs() const;
  bool displayTooSlow() const;
  // Frames this far apart (median) are no display at `display_hz`: more than one and a half of
  // its frame periods (frames skipped as a rule, not by chance).
  static bool tooSlow(double median_interval_s, double display_hz) {
    return median_interval_s > 1.5 / display_hz;
  }
  // The summary's "timing": soa_ms (configured, in frames, median, p95, p5, min, slipped: over
  // the SOA by half a frame), flash_rules (overlapped and gapless flashes, the least dark gap),
  // flash_ms, display, late_frames.
  nlohmann::json summary() const;
  double medianSoaS() const;

 private:
  struct Active {
    std::int64_t onset_sample;
  };
  bci::ParadigmSettings paradigm_;
  double rate_hz_;
  std::optional<double> last_presented_;
  std::int64_t frames_ = 0, late_frames_ = 0;
  std::vector<double> frame_intervals_s_;       // the last few hundred, for the display check
  std::vector<std::pair<int, Active>> active_;  // code, its onset, while lit
  std::vector<double> soa_samples_, duration_samples_;
  // A flash started while another was lit; on the frame right after a lit one; the dark gaps.
  std::int64_t overlapped_ = 0, gapless_ = 0;
  bool last_patch_lit_ = false;
  std::optional<std::int64_t> last_end_sample_;
  std::vector<double> gap_samples_;
  std::vector<std::int64_t> selection_onsets_;
  double selection_interrupted_s_ = 0.0;
};

}  // namespace arbci::session
