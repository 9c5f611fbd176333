// The default EEG source: a simulated subject. Background EEG with a 1/f spectrum shared in part
// between channels (volume conduction), alpha, line noise and eye blinks; every flash evokes a
// small visual response, and flashes of the attended stimuli an N2/P3 complex with a parietal
// maximum, its latency and amplitude varying from trial to trial. A selection's feedback evokes
// an error-related potential at fronto-central sites (a negativity near 250 ms and a positivity
// near 350 ms), large when the feedback disagrees with what the subject attends and small when it
// agrees (docs/errp.md gives the sources). Deterministic for a seed and the same sequence of calls.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "arbci/bci/eeg_source.h"
#include "arbci/bci/sample_clock.h"

namespace arbci::bci {

// The ERP of one subject.
struct SubjectProfile {
  double p3_amplitude_uv = 5.0;
  double p3_latency_s = 0.35;
  double p3_width_s = 0.09;  // standard deviation of the Gaussian
  double n2_amplitude_uv = -2.0;
  double n2_latency_s = 0.24;
  double n2_width_s = 0.035;
  double latency_jitter_s = 0.04;      // trial-to-trial standard deviation
  double amplitude_variability = 0.4;  // log-normal sigma of the trial's amplitude factor
  double vep_amplitude_uv = 2.0;       // N1/P2 evoked by every flash, occipital
  // The error-related potential to a selection's feedback (at FCz; less elsewhere), when the
  // feedback disagrees with the subject's intention; feedback that agrees evokes the same shape
  // at `errp_correct_fraction` of the size. Jitter and variability as for the P3.
  double errp_ne_amplitude_uv = -8.0;
  double errp_ne_latency_s = 0.25;
  double errp_ne_width_s = 0.035;
  double errp_pe_amplitude_uv = 10.0;
  double errp_pe_latency_s = 0.35;
  double errp_pe_width_s = 0.045;
  double errp_correct_fraction = 0.2;
  double errp_latency_jitter_s = 0.025;

  // A plausible subject drawn from `seed` (amplitude 3.5-7 uV, P3 latency 300-420 ms; ErrP
  // negativity 220-290 ms, -6 to -10 uV; positivity 320-400 ms, 8-13 uV, at FCz).
  static SubjectProfile drawn(std::uint64_t seed);
};

// The settings (seed, montage, rate, block size, line frequency, photodiode channel) take their
// defaults from bci::subjectSchema() (bci/settings.h); the rest is the model's physiology.
struct SimulatedSubjectConfig {
  SimulatedSubjectConfig();  // the schema's defaults
  std::vector<std::string> montage;
  double rate_hz;
  int block_size;
  std::uint64_t seed;
  double background_uv = 7.0;      // RMS of the 1/f background per channel
  double shared_background = 0.5;  // fraction of the background's variance common to all channels
  double alpha_hz = 10.0;
  double alpha_uv = 4.0;  // RMS at occipital channels
  double line_hz;
  double line_uv = 1.5;
  double blinks_per_minute = 6.0;
  double blink_uv = 100.0;                // at Fp1/Fp2; less further back
  std::optional<SubjectProfile> profile;  // default: SubjectProfile::drawn(seed)
  // A virtual photodiode on the HMD's patch, as an extra channel after the montage: 0 while the
  // patch is dark, `photodiode_lit_uv` while it is lit, switching on the first sample taken at or
  // after the presentation that changed it.
  bool photodiode = false;
  std::string photodiode_channel;
  double photodiode_lit_uv = 1000.0;
};

class SimulatedSubject final : public EegSource {
 public:
  // `clock` paces the source (WallClock: real time; ManualClock: the caller's; UnboundedClock: as
  // fast as it is read). Throws std::invalid_argument for an empty montage or a bad rate.
  SimulatedSubject(const SimulatedSubjectConfig& config, std::shared_ptr<const SampleClock> clock);
  ~SimulatedSubject() override;

  const SignalInfo& info() const override { return info_; }
  std::vector<Block> poll(int max_blocks = 64) override;
  void present(const StimulusEvent& event) override;
  void attend(const std::set<int>& codes) override { attended_ = codes; }
  void feedback(std::int64_t sample, const std::set<int>& codes) override;
  void displayed(double host_s, bool patch_lit) override;
  double knownLatencyS() const override { return clock_->deliveryLagS(); }
  // "simulated subject (seed 1: P3 5.2 uV at 352 ms), 8 channels at 256 Hz".
  std::string describe() const override;
  const SubjectProfile& profile() const { return profile_; }
  std::int64_t samplesGenerated() const { return generated_; }

 private:
  struct Generator;
  struct ActiveResponse {
    std::int64_t onset;
    double p3_latency, p3_scale, n2_scale;
    bool attended;
    // A feedback's ErrP (not a flash's response): its size relative to an error's.
    double errp_scale = 0.0;
  };
  float evoked(int channel, std::int64_t sample) const;

  SimulatedSubjectConfig config_;
  SubjectProfile profile_;
  SignalInfo info_;
  std::shared_ptr<const SampleClock> clock_;
  std::unique_ptr<Generator> generator_;
  std::set<int> attended_;
  std::vector<ActiveResponse> responses_;
  // Photodiode level changes (first sample, lit), in order; the last one before `generated_` is
  // kept as the current level.
  std::vector<std::pair<std::int64_t, bool>> screen_;
  bool screen_lit_ = false;
  std::mt19937_64 trial_random_;
  // The ErrPs' own draws: feedback does not change a seed's P300 trial-to-trial variation.
  std::mt19937_64 errp_random_;
  std::int64_t generated_ = 0;
};

}  // namespace arbci::bci
