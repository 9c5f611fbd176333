// The pre-flight check before the calibration run: camera frames arrive and show the reference
// marker, the EEG flows at its rate and its channels are not graded bad (gates.signal_quality),
// and the robot answers STATUS. It watches the cycle for at
// least `min_s` and passes once all hold; past `timeout_s` (of session time and of the wall
// clock both: a robot answers on the wall clock even when the session's is simulated) it fails,
// each failure naming the session file's key to look at.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace arbci::session {

struct PreflightSettings {
  double min_s = 1.0;          // the EEG rate is measured over at least this long (after the
                               // first samples' start-up backlog)
  double timeout_s = 5.0;      // session seconds, and wall seconds
  double eeg_rate_hz = 0.0;    // the source's
  double eeg_tolerance = 0.1;  // a rate off by more than this fraction fails
  // What to name in a failure: the key and a description of each source.
  std::string camera_key, camera_what;
  std::string eeg_key;
  int reference_id = 0;
  // The objects the session offers (marker ids): at least two must be seen to select between.
  std::vector<int> object_ids;
  std::string robot_key, robot_what;
  // The session folder's disk must have this much free (0: not checked); `disk_what` says how
  // it was reckoned.
  std::uintmax_t disk_needed = 0;
  std::string folder, disk_what;
  // gates.signal_quality: "ask" (a failure the experimenter may override), "refuse" or "off";
  // more bad channels than `bad_channels_allowed` fail it.
  std::string quality_gate = "off";
  int bad_channels_allowed = 0;
  // The display: frames every 1 / display_hz are what the flashes are timed in. A display whose
  // frames come slower (StimulusTiming::tooSlow) is a question where the timing gate would pause
  // the run for it (`display_question`: gates.timing "pause" with an experimenter): run with the
  // flashes off limits annotated, or cancel. 0: not checked.
  double display_hz = 0.0;
  double flash_ms = 0.0, soa_ms = 0.0;  // the paradigm's, for the question's figures
  bool display_question = false;
  // Failures known before the check begins (the display's: a missing HMD monitor); any fails
  // the pre-flight on its first frame.
  std::vector<std::string> known_failures;
};

// What the cycle saw on one frame.
struct PreflightObservation {
  double time_s = 0.0;  // session time
  double wall_s = 0.0;  // host clock
  bool camera_frame = false;
  std::optional<double> reference_age_s;  // since the reference marker was seen
  std::vector<int> objects_seen;          // offered objects whose pose is fresh now
  double max_pose_age_s = 0.0;            // the session's tracker.max_pose_age_s
  long long eeg_samples = 0;              // recorded so far
  bool robot_answered = false;
  bool robot_key_refused = false;           // it answered, with KEY MISMATCH
  std::optional<std::uintmax_t> disk_free;  // on the session folder's disk (unknown: unchecked)
  // The EEG channels graded bad ("C3: flat: ..."), of how many; none: not assessed yet.
  std::optional<std::vector<std::string>> bad_channels;
  int channels = 0;
  // A frame reached the screen since the last observation, and when (host clock).
  std::optional<double> frame_host_s;
};

// What the experimenter accepted when the last check asked: the channels as they are (the gate
// "ask"), the display as it is (the run's flashes annotated, no timing pauses).
struct PreflightAccepted {
  bool quality = false, display = false;
};

class Preflight {
 public:
  enum class State { Idle, Running, Passed, Failed };
  explicit Preflight(PreflightSettings settings) : settings_(std::move(settings)) {}

  using Accepted = PreflightAccepted;
  void begin(const PreflightObservation& now, Accepted accepted = {});
  // Running: updates the state from this frame's observation.
  State update(const PreflightObservation& now);
  State state() const { return state_; }
  // Failed: one line per failure, each naming its key.
  const std::vector<std::string>& failures() const { return failures_; }
  // For the panel: one line per check with what was measured so far.
  std::vector<std::string> lines() const;
  // Failed only on what the experimenter may accept: the signal's quality (the gate "ask"), the
  // display's rate (display_question).
  bool questioned() const;
  bool qualityQuestioned() const;
  // The display's question ("" when none): the frame interval measured and what it does to the
  // flashes.
  std::string displayQuestion() const;
  // The median interval between the frames the check saw (seconds; none before 10 frames).
  std::optional<double> frameIntervalS() const;
  bool displayAccepted() const { return accepted_.display; }
  // The quality verdict once the check ended: "passed", "refused", "questioned", "accepted by the
  // experimenter" or "not checked".
  std::string qualityVerdict() const;
  double eegRateHz() const { return eeg_rate_hz_; }
  int cameraFrames() const { return camera_frames_; }

 private:
  std::vector<std::string> check(bool final) const;
  // "" when the channels pass the gate, else its failure.
  std::string qualityFailure() const;
  // "" when the display holds its rate (or is not judged), else its failure.
  std::string displayFailure() const;
  PreflightSettings settings_;
  State state_ = State::Idle;
  PreflightObservation first_, last_;
  int camera_frames_ = 0;
  bool reference_seen_ = false;
  std::set<int> objects_seen_;
  double eeg_rate_hz_ = 0.0;
  // The EEG's start-up backlog drains within this long of the first samples arriving.
  static constexpr double kSettleS = 0.25;
  // Samples that stop arriving for this long: the stream has stopped (blocks come every 60 ms).
  static constexpr double kSilentS = 0.5;
  std::optional<double> first_eeg_s_;             // when the first samples arrived
  std::optional<PreflightObservation> eeg_from_;  // where the rate is counted from
  PreflightObservation eeg_last_;                 // the last frame on which samples arrived
  std::vector<std::string> failures_;
  Accepted accepted_;
  std::vector<double> frame_intervals_s_;  // between the frames the check saw
  std::optional<double> last_frame_s_;
  // Frames the display is judged on, at the least.
  static constexpr int kDisplayFrames = 10;
};

}  // namespace arbci::session
