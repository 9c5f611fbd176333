#include "arbci/session/preflight.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "arbci/session/stimulus_timing.h"

namespace arbci::session {
namespace {

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[160];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

}  // namespace

void Preflight::begin(const PreflightObservation& now, Accepted accepted) {
  state_ = State::Running;
  accepted_ = accepted;
  frame_intervals_s_.clear();
  last_frame_s_.reset();
  first_ = last_ = now;
  camera_frames_ = 0;
  reference_seen_ = false;
  objects_seen_.clear();
  eeg_rate_hz_ = 0.0;
  eeg_from_.reset();
  first_eeg_s_.reset();
  eeg_last_ = now;
  failures_.clear();
}

Preflight::State Preflight::update(const PreflightObservation& now) {
  if (state_ != State::Running) return state_;
  last_ = now;
  if (!settings_.known_failures.empty()) {
    failures_ = check(true);
    state_ = State::Failed;
    return state_;
  }
  camera_frames_ += now.camera_frame;
  if (now.frame_host_s) {
    if (last_frame_s_) frame_intervals_s_.push_back(*now.frame_host_s - *last_frame_s_);
    last_frame_s_ = now.frame_host_s;
  }
  reference_seen_ |= now.reference_age_s && *now.reference_age_s <= now.max_pose_age_s;
  objects_seen_.insert(now.objects_seen.begin(), now.objects_seen.end());
  const double elapsed = now.time_s - first_.time_s;
  // The rate is counted from a moment after the first samples arrived: a source's first
  // deliveries carry what it buffered before the session asked (a start-up backlog), which would
  // read as a rate too high. It is counted between frames on which samples arrived (not up to
  // now): over a second, a block of 15 samples counted or not would be 6 % of the rate.
  const bool arrived = now.eeg_samples > eeg_last_.eeg_samples;
  if (arrived) {
    if (!first_eeg_s_) first_eeg_s_ = now.time_s;
    if (!eeg_from_ && now.time_s - *first_eeg_s_ >= kSettleS) eeg_from_ = now;
    eeg_last_ = now;
  }
  const double counted = eeg_from_ ? eeg_last_.time_s - eeg_from_->time_s : 0.0;
  if (counted > 0.0)
    eeg_rate_hz_ = static_cast<double>(eeg_last_.eeg_samples - eeg_from_->eeg_samples) / counted;
  const bool display_judged =
      settings_.display_hz <= 0.0 || static_cast<int>(frame_intervals_s_.size()) >= kDisplayFrames;
  if (elapsed < settings_.min_s || (first_eeg_s_ && counted < settings_.min_s) || !display_judged) {
    // Still counting, unless time is up: then judge what there is.
    if (elapsed < settings_.timeout_s) return state_;
  }
  if (elapsed >= settings_.min_s && check(false).empty()) {
    state_ = State::Passed;
  } else if (elapsed >= settings_.timeout_s && now.wall_s - first_.wall_s >= settings_.timeout_s) {
    failures_ = check(true);
    state_ = State::Failed;
  }
  return state_;
}

std::vector<std::string> Preflight::check(bool final) const {
  std::vector<std::string> out = settings_.known_failures;
  const double waited = last_.time_s - first_.time_s;
  if (camera_frames_ < 2) {
    out.push_back(settings_.camera_key + ": " + std::to_string(camera_frames_) +
                  " camera frame(s) in " + format("%.1f s", waited) + " from " +
                  settings_.camera_what + " (cannot be decoded, or no picture)");
  } else if (!reference_seen_) {
    out.push_back("world.reference.id: the reference marker " +
                  std::to_string(settings_.reference_id) + " was not seen in " +
                  std::to_string(camera_frames_) +
                  " camera frames (in view? the right id? see the Threshold panel)");
  }
  // Fewer than two objects in view: nothing to select between (the paradigm would wait forever).
  if (reference_seen_ && settings_.object_ids.size() >= 2 && objects_seen_.size() < 2) {
    std::string missing;
    for (int id : settings_.object_ids)
      if (!objects_seen_.count(id)) missing += (missing.empty() ? "" : ", ") + std::to_string(id);
    out.push_back("world.objects: " + std::to_string(objects_seen_.size()) + " of the " +
                  std::to_string(settings_.object_ids.size()) + " objects seen in " +
                  std::to_string(camera_frames_) + " camera frames (not seen: " + missing +
                  "); at least 2 must be on the table and in view");
  }
  const double rate = settings_.eeg_rate_hz;
  const double silent = last_.time_s - eeg_last_.time_s;
  if (eeg_rate_hz_ <= 0.0) {
    out.push_back(settings_.eeg_key + ": no EEG sample in " + format("%.1f s", waited));
  } else if (silent > kSilentS) {
    out.push_back(settings_.eeg_key + ": no EEG sample for the last " + format("%.1f s", silent));
  } else if (std::abs(eeg_rate_hz_ - rate) > settings_.eeg_tolerance * rate) {
    out.push_back(settings_.eeg_key + ": EEG samples arrive at " +
                  format("%.1f Hz, the source says %.1f Hz", eeg_rate_hz_, rate));
  }
  if (settings_.disk_needed > 0 && last_.disk_free && *last_.disk_free < settings_.disk_needed) {
    out.push_back("--out: the disk holding " + settings_.folder + " has " +
                  format("%.0f MB free; this run needs ", std::floor(*last_.disk_free / 1e6)) +
                  settings_.disk_what +
                  ": free some space, choose another folder, or keep fewer "
                  "screenshots (hmd.screenshots)");
  }
  if (std::string quality = qualityFailure(); !quality.empty()) out.push_back(std::move(quality));
  if (std::string display = displayFailure(); !display.empty()) out.push_back(std::move(display));
  if (!last_.robot_answered && last_.robot_key_refused) {
    out.push_back(settings_.robot_key + ": " + settings_.robot_what +
                  " answered that our key is not its key: give both sides the same robot.key_file "
                  "(arbci robot keygen makes one)");
  } else if (!last_.robot_answered) {
    out.push_back(settings_.robot_key + ": " + settings_.robot_what + " did not answer STATUS" +
                  (final ? format(" in %.1f s", last_.wall_s - first_.wall_s) : ""));
  }
  return out;
}

std::optional<double> Preflight::frameIntervalS() const {
  if (static_cast<int>(frame_intervals_s_.size()) < kDisplayFrames) return std::nullopt;
  std::vector<double> sorted = frame_intervals_s_;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                   sorted.end());
  return sorted[sorted.size() / 2];
}

std::string Preflight::displayQuestion() const {
  const auto interval = frameIntervalS();
  if (settings_.display_hz <= 0.0 || !interval ||
      !StimulusTiming::tooSlow(*interval, settings_.display_hz))
    return "";
  // The flashes are timed in seconds and shown on the frames there are: a flash stays lit
  // until the first frame after its time, an onset waits for the first frame at or after it.
  const double frame_ms = 1000.0 / settings_.display_hz, got_ms = *interval * 1000.0;
  const double flash_ms = std::max(1.0, std::round(settings_.flash_ms / frame_ms)) * frame_ms;
  const double shown_ms = std::max(1.0, std::ceil(flash_ms / got_ms - 1e-9)) * got_ms;
  const double soa_ms = std::max(1.0, std::round(settings_.soa_ms / frame_ms)) * frame_ms;
  const double soa_shown_ms = std::ceil(soa_ms / got_ms - 1e-9) * got_ms;
  char text[400];
  int n = std::snprintf(text, sizeof text,
                        "display: a frame every %.0f ms (%.1f Hz; display_hz %.0f asks for %.1f "
                        "ms): ",
                        got_ms, 1.0 / *interval, settings_.display_hz, frame_ms);
  // A flash that still fits its frames keeps its length: only what changes is said.
  if (std::lround(shown_ms) != std::lround(flash_ms))
    n += std::snprintf(text + n, sizeof text - static_cast<size_t>(n),
                       "flashes will last about %.0f ms instead of %.0f, and ", shown_ms, flash_ms);
  std::snprintf(text + n, sizeof text - static_cast<size_t>(n),
                "onsets come about %.0f ms apart instead of %.0f", soa_shown_ms, soa_ms);
  return text;
}

std::string Preflight::displayFailure() const {
  if (accepted_.display) return "";
  std::string question = displayQuestion();
  if (question.empty()) return "";
  return question + (settings_.display_question
                         ? ": run annotated (every flash off limits noted; no timing pauses), or "
                           "cancel and free the PC or the display"
                         : " (gates.timing)");
}

std::string Preflight::qualityFailure() const {
  if (settings_.quality_gate == "off" || accepted_.quality) return "";
  if (!last_.bad_channels)
    return settings_.eeg_key + ": the channels' quality is not known yet (it needs 2 s of signal)";
  const auto& bad = *last_.bad_channels;
  if (static_cast<int>(bad.size()) <= settings_.bad_channels_allowed) return "";
  std::string text = "gates.signal_quality: " + std::to_string(bad.size()) + " of " +
                     std::to_string(last_.channels) + " EEG channels bad (";
  for (size_t i = 0; i < bad.size(); ++i) text += (i ? "; " : "") + bad[i];
  text += "): check the electrodes in the EEG panel";
  if (settings_.quality_gate == "ask") text += ", or start anyway";
  return text;
}

bool Preflight::questioned() const {
  if (state_ != State::Failed || failures_.empty()) return false;
  // Every failure is one the experimenter may accept: everything else passed.
  for (const std::string& f : failures_) {
    const bool quality = f.rfind("gates.signal_quality", 0) == 0 &&
                         settings_.quality_gate == "ask" && !accepted_.quality;
    const bool display = f.rfind("display:", 0) == 0 && settings_.display_question;
    if (!quality && !display) return false;
  }
  return true;
}

bool Preflight::qualityQuestioned() const {
  if (!questioned()) return false;
  for (const std::string& f : failures_)
    if (f.rfind("gates.signal_quality", 0) == 0) return true;
  return false;
}

std::string Preflight::qualityVerdict() const {
  if (settings_.quality_gate == "off") return "not checked";
  if (accepted_.quality) return "accepted by the experimenter";
  if (state_ == State::Passed) return "passed";
  for (const std::string& f : failures_)
    if (f.rfind("gates.signal_quality", 0) == 0)
      return settings_.quality_gate == "ask" ? "questioned" : "refused";
  return last_.bad_channels ? "passed" : "not assessed";
}

std::vector<std::string> Preflight::lines() const {
  std::vector<std::string> out;
  switch (state_) {
    case State::Idle:
      return out;
    case State::Passed:
      out.push_back("pre-flight passed: " + std::to_string(camera_frames_) +
                    " camera frames with the reference and " +
                    std::to_string(objects_seen_.size()) + " of " +
                    std::to_string(settings_.object_ids.size()) + " objects, " +
                    format("EEG at %.1f Hz, the robot answers", eeg_rate_hz_));
      return out;
    case State::Failed:
      out.emplace_back(questioned()
                           ? "pre-flight: all passed but what you may accept (Start checks "
                             "again; the buttons below accept it):"
                           : "pre-flight FAILED (Start checks again):");
      for (const std::string& f : failures_) out.push_back("  " + f);
      return out;
    case State::Running:
      out.emplace_back("pre-flight: checking cameras, reference, EEG and robot ...");
      for (const std::string& f : check(false)) out.push_back("  waiting: " + f);
      return out;
  }
  return out;
}

}  // namespace arbci::session
