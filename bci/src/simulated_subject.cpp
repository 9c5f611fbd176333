#include "arbci/bci/simulated_subject.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "arbci/core/seeds.h"
#include "scalp_topography.h"

namespace arbci::bci {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// 1/f noise: the sum of one-pole low-passes of equal variance with corners spaced by octaves
// from 0.1 Hz to the Nyquist rate.
class PinkNoise {
 public:
  explicit PinkNoise(double rate) {
    for (double corner = 0.1; corner < rate / 2.0; corner *= 2.0) {
      const double pole = std::exp(-kTwoPi * corner / rate);
      poles_.push_back(pole);
      gains_.push_back(std::sqrt(1.0 - pole * pole));  // unit variance per stage
      states_.push_back(0.0);
    }
    norm_ = 1.0 / std::sqrt(static_cast<double>(poles_.size()));
  }
  // Starts in the stationary state, so the first seconds are not quieter.
  void settle(std::mt19937_64& random, std::normal_distribution<double>& normal) {
    for (double& s : states_) s = normal(random);
  }
  double next(std::mt19937_64& random, std::normal_distribution<double>& normal) {
    double sum = 0.0;
    for (size_t i = 0; i < poles_.size(); ++i) {
      states_[i] = poles_[i] * states_[i] + gains_[i] * normal(random);
      sum += states_[i];
    }
    return sum * norm_;
  }

 private:
  std::vector<double> poles_, gains_, states_;
  double norm_ = 1.0;
};

// A narrow-band oscillation: an AR(2) resonator driven by white noise, unit variance.
class Resonator {
 public:
  Resonator(double frequency, double rate, double radius = 0.992) {
    a1_ = 2.0 * radius * std::cos(kTwoPi * frequency / rate);
    a2_ = -radius * radius;
    const double variance = (1.0 - a2_) / ((1.0 + a2_) * ((1.0 - a2_) * (1.0 - a2_) - a1_ * a1_));
    drive_ = 1.0 / std::sqrt(variance);
  }
  double next(double white) {
    const double y = a1_ * y1_ + a2_ * y2_ + drive_ * white;
    y2_ = y1_;
    y1_ = y;
    return y;
  }

 private:
  double a1_ = 0.0, a2_ = 0.0, drive_ = 1.0, y1_ = 0.0, y2_ = 0.0;
};

double gaussian(double t, double centre, double width) {
  const double z = (t - centre) / width;
  return std::exp(-0.5 * z * z);
}

}  // namespace

SubjectProfile SubjectProfile::drawn(std::uint64_t seed) {
  std::mt19937_64 random(core::seedOf(seed, core::RandomStream::SubjectProfile));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SubjectProfile p;
  p.p3_amplitude_uv = 4.5 + 3.5 * unit(random);
  p.p3_latency_s = 0.30 + 0.12 * unit(random);
  p.p3_width_s = 0.07 + 0.04 * unit(random);
  p.n2_amplitude_uv = -(1.0 + 2.0 * unit(random));
  p.n2_latency_s = 0.20 + 0.06 * unit(random);
  p.latency_jitter_s = 0.03 + 0.03 * unit(random);
  // Drawn after the P300's, so a seed's P300 stays what it was.
  p.errp_ne_amplitude_uv = -(6.0 + 4.0 * unit(random));
  p.errp_ne_latency_s = 0.22 + 0.07 * unit(random);
  p.errp_pe_amplitude_uv = 8.0 + 5.0 * unit(random);
  p.errp_pe_latency_s = p.errp_ne_latency_s + 0.10 + 0.01 * unit(random);
  return p;
}

struct SimulatedSubject::Generator {
  std::mt19937_64 random;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::vector<PinkNoise> own;      // per channel
  PinkNoise shared;                // common to all channels
  std::vector<double> shared_mix;  // per channel, random sign and size
  Resonator alpha;
  std::vector<double> line_amplitude, line_phase;
  std::vector<ScalpWeights> weights;
  std::int64_t next_blink = -1;
  std::int64_t blink_start = -1, blink_length = 0;
  double blink_size = 1.0;

  Generator(const SimulatedSubjectConfig& c)
      : random(c.seed), shared(c.rate_hz), alpha(c.alpha_hz, c.rate_hz) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const std::string& name : c.montage) {
      own.emplace_back(c.rate_hz);
      own.back().settle(random, normal);
      shared_mix.push_back(0.8 + 0.4 * unit(random));
      line_amplitude.push_back(c.line_uv * (0.5 + unit(random)));
      line_phase.push_back(kTwoPi * unit(random));
      weights.push_back(scalpWeights(name));
    }
    shared.settle(random, normal);
  }
};

std::string SimulatedSubject::describe() const {
  char text[160];
  std::snprintf(text, sizeof text,
                "simulated subject (seed %llu: P3 %.1f uV at %.0f ms), %zu channels at %.0f Hz",
                static_cast<unsigned long long>(config_.seed), profile_.p3_amplitude_uv,
                profile_.p3_latency_s * 1000.0, config_.montage.size(), config_.rate_hz);
  return text;
}

SimulatedSubject::SimulatedSubject(const SimulatedSubjectConfig& config,
                                   std::shared_ptr<const SampleClock> clock)
    : config_(config),
      profile_(config.profile ? *config.profile : SubjectProfile::drawn(config.seed)),
      clock_(std::move(clock)),
      trial_random_(core::seedOf(config.seed, core::RandomStream::SubjectTrials)),
      errp_random_(core::seedOf(config.seed, core::RandomStream::SubjectErrp)) {
  if (config.montage.empty())
    throw std::invalid_argument("simulated subject: the montage has no channels");
  if (!(config.rate_hz >= 32.0 && config.rate_hz <= 20000.0)) {
    throw std::invalid_argument("simulated subject: sampling rate must be 32-20000 Hz");
  }
  if (config.block_size <= 0)
    throw std::invalid_argument("simulated subject: block size must be positive");
  if (!clock_) throw std::invalid_argument("simulated subject: no clock");
  info_.rate_hz = config.rate_hz;
  info_.block_size = config.block_size;
  info_.channels = config.montage;
  if (config.photodiode) info_.channels.push_back(config.photodiode_channel);
  generator_ = std::make_unique<Generator>(config_);
}

SimulatedSubject::~SimulatedSubject() = default;

void SimulatedSubject::present(const StimulusEvent& event) {
  std::normal_distribution<double> normal(0.0, 1.0);
  ActiveResponse response{};
  response.onset = event.sample;
  response.attended = attended_.count(event.code) > 0;
  response.p3_latency = profile_.p3_latency_s + profile_.latency_jitter_s * normal(trial_random_);
  response.p3_scale =
      std::exp(profile_.amplitude_variability * normal(trial_random_) -
               0.5 * profile_.amplitude_variability * profile_.amplitude_variability);
  response.n2_scale = std::exp(0.3 * normal(trial_random_));
  responses_.push_back(response);
}

void SimulatedSubject::feedback(std::int64_t sample, const std::set<int>& codes) {
  std::normal_distribution<double> normal(0.0, 1.0);
  ActiveResponse response{};
  response.onset = sample;
  response.attended = false;
  const bool agrees = !attended_.empty() && codes == attended_;

  response.errp_scale = agrees ? profile_.errp_correct_fraction : 1.0;
  // The shift of the whole complex, and its size this time.
  response.p3_latency = profile_.errp_latency_jitter_s * normal(errp_random_);
  response.p3_scale =
      std::exp(profile_.amplitude_variability * normal(errp_random_) -
               0.5 * profile_.amplitude_variability * profile_.amplitude_variability);
  responses_.push_back(response);
}

void SimulatedSubject::displayed(double host_s, bool patch_lit) {
  const auto first =
      static_cast<std::int64_t>(std::ceil(clock_->sampleAtHost(host_s, config_.rate_hz) - 1e-6));
  screen_.emplace_back(std::max(first, generated_), patch_lit);
}

float SimulatedSubject::evoked(int channel, std::int64_t sample) const {
  const ScalpWeights& w = generator_->weights[static_cast<size_t>(channel)];
  double value = 0.0;
  for (const ActiveResponse& r : responses_) {
    const double t = (sample - r.onset) / config_.rate_hz;
    if (t < 0.0 || t > 1.0) continue;
    if (r.errp_scale > 0.0) {
      const double shift = r.p3_latency, size = w.errp * r.errp_scale * r.p3_scale;
      value +=
          size * (profile_.errp_ne_amplitude_uv *
                      gaussian(t, profile_.errp_ne_latency_s + shift, profile_.errp_ne_width_s) +
                  profile_.errp_pe_amplitude_uv *
                      gaussian(t, profile_.errp_pe_latency_s + shift, profile_.errp_pe_width_s));
      continue;
    }
    // N1/P2 to every flash.
    value += w.vep * profile_.vep_amplitude_uv *
             (-gaussian(t, 0.15, 0.02) + 0.8 * gaussian(t, 0.21, 0.03));
    if (!r.attended) continue;
    const double latency_shift = r.p3_latency - profile_.p3_latency_s;
    value += w.n2 * profile_.n2_amplitude_uv * r.n2_scale *
             gaussian(t, profile_.n2_latency_s + 0.5 * latency_shift, profile_.n2_width_s);
    value += w.p3 * profile_.p3_amplitude_uv * r.p3_scale *
             gaussian(t, r.p3_latency, profile_.p3_width_s);
  }
  return static_cast<float>(value);
}

std::vector<Block> SimulatedSubject::poll(int max_blocks) {
  std::vector<Block> blocks;
  const std::int64_t available = clock_->available(config_.rate_hz);
  Generator& g = *generator_;
  const int channels = static_cast<int>(config_.montage.size());
  const double blink_mean_gap =
      config_.blinks_per_minute > 0.0 ? 60.0 / config_.blinks_per_minute * config_.rate_hz : 0.0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  while (static_cast<int>(blocks.size()) < max_blocks &&
         generated_ + config_.block_size <= available) {
    Block block(generated_, info_.channelCount(), config_.block_size);
    for (int s = 0; s < config_.block_size; ++s) {
      const std::int64_t n = generated_ + s;
      const double time = n / config_.rate_hz;
      // Blinks arrive as a Poisson process; each lasts 300-450 ms.
      if (blink_mean_gap > 0.0) {
        if (g.next_blink < 0)
          g.next_blink =
              n + static_cast<std::int64_t>(-std::log(1.0 - unit(g.random)) * blink_mean_gap);
        if (n == g.next_blink) {
          g.blink_start = n;
          g.blink_length =
              static_cast<std::int64_t>((0.30 + 0.15 * unit(g.random)) * config_.rate_hz);
          g.blink_size = 0.6 + 0.8 * unit(g.random);
          g.next_blink =
              n + g.blink_length +
              static_cast<std::int64_t>(-std::log(1.0 - unit(g.random)) * blink_mean_gap);
        }
      }
      double blink = 0.0;
      if (g.blink_start >= 0 && n < g.blink_start + g.blink_length) {
        const double phase = static_cast<double>(n - g.blink_start) / g.blink_length;
        blink = config_.blink_uv * g.blink_size * 0.5 * (1.0 - std::cos(kTwoPi * phase));
      }
      const double shared = g.shared.next(g.random, g.normal);
      const double alpha = g.alpha.next(g.normal(g.random));
      const double own_weight = std::sqrt(1.0 - config_.shared_background);
      const double shared_weight = std::sqrt(config_.shared_background);
      for (int c = 0; c < channels; ++c) {
        const ScalpWeights& w = g.weights[static_cast<size_t>(c)];
        double v = config_.background_uv *
                   (own_weight * g.own[static_cast<size_t>(c)].next(g.random, g.normal) +
                    shared_weight * g.shared_mix[static_cast<size_t>(c)] * shared);
        v += config_.alpha_uv * w.alpha * alpha;
        v += g.line_amplitude[static_cast<size_t>(c)] *
             std::sin(kTwoPi * config_.line_hz * time + g.line_phase[static_cast<size_t>(c)]);
        v += w.blink * blink;
        v += evoked(c, n);
        block.at(c, s) = static_cast<float>(v);
      }
      if (config_.photodiode) {
        size_t used = 0;
        while (used < screen_.size() && screen_[used].first <= n)
          screen_lit_ = screen_[used++].second;
        screen_.erase(screen_.begin(), screen_.begin() + static_cast<std::ptrdiff_t>(used));
        block.at(channels, s) = screen_lit_ ? static_cast<float>(config_.photodiode_lit_uv) : 0.0f;
      }
    }
    generated_ += config_.block_size;
    blocks.push_back(std::move(block));
    // Responses more than a second old are over.
    std::erase_if(responses_, [&](const ActiveResponse& r) {
      return r.onset + static_cast<std::int64_t>(config_.rate_hz) < generated_;
    });
  }
  return blocks;
}

}  // namespace arbci::bci
