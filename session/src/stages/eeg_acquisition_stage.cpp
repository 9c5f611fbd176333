#include "arbci/session/stages/eeg_acquisition_stage.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "arbci/session/eeg_sources.h"

namespace arbci::session {

void EegAcquisitionSettings::validate() const {
  if (!eeg.file.empty() && !std::filesystem::exists(eeg.file))
    throw SessionConfigError(session_file + ": eeg.file = \"" + eeg.file + "\": no such file");
}

EegAcquisitionStage::EegAcquisitionStage(const EegAcquisitionSettings& settings,
                                         OpenedEegSource source, Clock& clock,
                                         const StageServices& services)
    : settings_(settings), s_(services) {
  const EegSettings& eeg = settings_.eeg;
  bci::AcquisitionSettings acquisition;
  acquisition.latency_s = eeg.latency_ms / 1000.0;
  acquisition_ = std::make_unique<bci::Acquisition>(
      std::move(source.source), source.clock,
      clock.stepped() ? bci::Acquisition::Mode::Stepped : bci::Acquisition::Mode::Live,
      acquisition);
  const bci::SignalInfo& all = acquisition_->info();
  all_info_ = std::make_shared<const bci::SignalInfo>(all);
  eeg_info_ = all;
  if (!eeg.photodiode_channel.empty()) {
    const auto found = std::find(all.channels.begin(), all.channels.end(), eeg.photodiode_channel);
    if (found == all.channels.end()) {
      std::string names;
      for (const auto& c : all.channels) names += (names.empty() ? "" : ", ") + c;
      throw SessionConfigError(
          settings_.session_file + ": eeg.photodiode_channel = \"" + eeg.photodiode_channel +
          "\": the EEG source has no such channel (it has: " + names + "; use \"\" for none)");
    }
    photodiode_ = static_cast<int>(found - all.channels.begin());
    eeg_info_.channels.erase(eeg_info_.channels.begin() + photodiode_);
  }
  bci::Acquisition* acquisition_ptr = acquisition_.get();
  clock.setSampleMap(
      [acquisition_ptr](double host_s) { return acquisition_ptr->firstSampleAtOrAfter(host_s); },
      [acquisition_ptr](double host_s) { return acquisition_ptr->sampleAt(host_s); });
  acquisition_->start();
}

EegAcquisitionStage::~EegAcquisitionStage() {
  acquisition_->stop();
}

void EegAcquisitionStage::toSource(const Cycle& cycle) {
  // What the subject attends from the new selection on, what the screen showed (the photodiode
  // patch, the flashes) and the feedback it saw, in the order they reached the subject.
  const auto& started = cycle.previous.paradigm.selection_started;
  const Presentation& shown = cycle.record.presentation;
  const int nominal_duration = static_cast<int>(settings_.flash_s * settings_.eeg.rate_hz + 0.5);
  acquisition_->withSource([&](bci::EegSource& source) {
    if (started) source.attend(started->attended);
    if (shown.patch) source.displayed(shown.host_s, *shown.patch);
    for (const Presentation::Onset& onset : shown.onsets) {
      source.present({onset.sample, onset.flash.code, onset.flash.target, nominal_duration,
                      onset.flash.known});
    }
    if (shown.feedback) source.feedback(shown.sample, shown.feedback->codes);
  });
}

bci::Block EegAcquisitionStage::eegOnly(const bci::Block& block) const {
  if (photodiode_ < 0) return block;
  bci::Block out(block.first_sample, block.channels - 1, block.samples);
  out.data = bci::withoutChannel(block.data, block.channels, block.samples, photodiode_);
  return out;
}

void EegAcquisitionStage::watchDelivery(Cycle& cycle, bool delivered) {
  EegPart& out = cycle.record.eeg;
  bool finished = false;
  acquisition_->withSource([&](bci::EegSource& source) { finished = source.finished(); });
  if (delivered || !last_delivery_s_) {
    if (delivered) {
      last_delivery_s_ = cycle.time_s;
      last_delivery_host_s_ = cycle.host_s;
    }
    silence_.clear();
  }
  // (Blocks the acquisition thread still holds come within a cycle or two.)
  if (finished && !delivered && last_delivery_s_ && cycle.time_s - *last_delivery_s_ >= 0.25) {
    // Every sample of the file delivered: the recording and the paradigm have nothing more to go
    // on. The run ends as a fault, with its summary and the recording whole.
    char text[240];
    std::snprintf(text, sizeof text,
                  "the EEG source ended: %s delivered its last sample (%.1f s of signal); the run "
                  "cannot go on without EEG",
                  settings_.eeg.file.empty() ? "the source" : settings_.eeg.file.c_str(),
                  static_cast<double>(next_sample_) / acquisition_->info().rate_hz);
    out.fault = text;
    cycle.end(text, "fault");
    return;
  }
  // Live: silence on the host's clock (a session whose cycles stall still sees the time pass).
  if (acquisition_->mode() != bci::Acquisition::Mode::Live || !last_delivery_s_) return;
  const double silent = cycle.host_s - last_delivery_host_s_;
  if (silent < kSilentS) return;
  char text[240];
  std::snprintf(text, sizeof text,
                "no EEG sample from %s for %.1f s (the last arrived at session time %.1f s)",
                sourceLine().empty() ? "the source" : sourceLine().c_str(), silent,
                *last_delivery_s_);
  // The text changes each second it lasts; the fault is logged as it starts.
  if (silence_.empty()) silence_ = text;
  out.fault = silence_;
}

void EegAcquisitionStage::endIfNobodyCanHelp(Cycle& cycle) {
  const std::string& fault = cycle.record.eeg.fault;
  if (fault.empty()) {
    fault_since_host_s_.reset();
    return;
  }
  if (!fault_since_host_s_) fault_since_host_s_ = cycle.host_s;
  // A source in fault (its own word, or its silence) that nobody at a window can bring back.
  if (!settings_.experimenter && cycle.host_s - *fault_since_host_s_ >= kSilentEndS)
    cycle.end(fault + "; nobody at the window to bring it back", "fault");
}

void EegAcquisitionStage::take(Cycle& cycle) {
  EegPart& out = cycle.record.eeg;
  out.info = all_info_;
  for (bci::SampleLoss& loss : acquisition_->takeLosses()) out.losses.push_back(std::move(loss));
  for (bci::Block& block : acquisition_->take()) {
    next_sample_ = block.first_sample + block.samples;
    out.eeg_blocks.push_back(eegOnly(block));
    out.blocks.push_back(std::move(block));
  }
}

void EegAcquisitionStage::noteStall(Cycle& cycle, const bci::DeliveryStall& stall) {
  const double rate = acquisition_->info().rate_hz;
  const double held_s = stall.host_s - stall.since_host_s;
  std::vector<std::int64_t> uncertain;
  for (const auto& [host_s, sample] : recent_onsets_) {
    if (host_s > stall.since_host_s && host_s <= stall.host_s) uncertain.push_back(sample);
  }
  ++stalls_.count;
  stalls_.longest_s = std::max(stalls_.longest_s, held_s);
  stalls_.samples += stall.samples;
  stalls_.uncertain_flashes += static_cast<int>(uncertain.size());
  char text[200];
  std::snprintf(text, sizeof text,
                "EEG delivery stalled %.2f s: %lld samples arrived at once; %zu flash stamp(s) "
                "in it extrapolated",
                held_s, static_cast<long long>(stall.samples), uncertain.size());
  cycle.annotate(stall.first_sample, text);
  for (const std::int64_t sample : uncertain)
    cycle.annotate(sample, "stamp uncertain: EEG delivery stalled");
  s_.log.write("eeg_stall", cycle.time_s,
               {{"first_sample", stall.first_sample},
                {"samples", stall.samples},
                {"seconds_of_signal", static_cast<double>(stall.samples) / rate},
                {"held_s", held_s},
                {"late_s", stall.late_s},
                {"uncertain_flashes", uncertain.size()}});
  s_.tell.say(cycle.time_s, Severity::Warning, text);
}

void EegAcquisitionStage::step(Cycle& cycle) {
  toSource(cycle);
  if (cycle.clock.stepped()) acquisition_->advanceTo(cycle.time_s);
  take(cycle);
  EegPart& out = cycle.record.eeg;
  // This cycle's onsets (the frame the presentation stage just stamped), as the source was told:
  // a stall taken now may have held up the samples their stamps rest on.
  const Presentation& shown = cycle.record.presentation;
  for (const Presentation::Onset& onset : shown.onsets)
    recent_onsets_.emplace_back(shown.host_s, onset.sample);
  while (!recent_onsets_.empty() && recent_onsets_.front().first < cycle.host_s - 60.0)
    recent_onsets_.pop_front();
  for (bci::DeliveryStall& stall : acquisition_->takeStalls()) {
    noteStall(cycle, stall);
    out.stalls.push_back(stall);
  }
  out.lost_samples = acquisition_->lostSamples();
  const bci::ClockReport clock = acquisition_->clockReport();
  out.drift_ppm = clock.drift_ppm;
  out.drift_reliable = clock.drift_reliable;
  out.jitter_ms = clock.jitter_s * 1000.0;
  if (clock.drift_at_bound && clock.drift_uncertainty_ppm < bci::ClockModel::kMaxDriftPpm / 5 &&
      !drift_warned_) {
    // The data disagree with the nominal rate by more than any amplifier's crystal would (and
    // the fit is sure of it: a young fit over a second or two can touch the bound by chance).
    char text[240];
    std::snprintf(text, sizeof text,
                  "the EEG clock runs more than %.0f ppm off the source's %.1f Hz (fit held at the "
                  "bound): check eeg.rate_hz against the amplifier; stamps are uncertain",
                  bci::ClockModel::kMaxDriftPpm, acquisition_->info().rate_hz);
    s_.log.write("eeg_clock", cycle.time_s, {{"warning", text}});
    s_.tell.say(cycle.time_s, Severity::Warning, text);
    drift_warned_ = true;
  }
  if (out.lost_samples != lost_logged_) {
    s_.log.write("lost_samples", cycle.time_s,
                 {{"total", out.lost_samples}, {"new", out.lost_samples - lost_logged_}});
    s_.tell.say(cycle.time_s, Severity::Warning,
                std::to_string(out.lost_samples - lost_logged_) +
                    " EEG samples lost (see the recording's annotations)");
    lost_logged_ = out.lost_samples;
  }
  // A live source's fault (an LSL stream gone), logged when it starts and when it ends.
  acquisition_->withSource([&](bci::EegSource& source) {
    out.fault = source.fault();
    out.source_line = source.describe();
    out.impedance = source.impedance();
    // The amplifier's own markers (trigger box, photodiode) go into the recording as they are.
    for (bci::Annotation& marker : source.takeAnnotations()) {
      cycle.annotate(marker.sample, std::move(marker.text));
      ++source_markers_;
    }
  });
  if (const std::string fault = acquisition_->fault(); !fault.empty()) out.fault = fault;
  if (out.fault.empty()) watchDelivery(cycle, !out.blocks.empty());
  if (!out.blocks.empty()) last_delivery_host_s_ = cycle.host_s;
  endIfNobodyCanHelp(cycle);
  if (out.fault != fault_logged_) {
    s_.log.write("eeg_source", cycle.time_s,
                 {{"fault", out.fault}, {"state", out.fault.empty() ? "delivering" : "fault"}});
    if (out.fault.empty()) {
      s_.tell.say(cycle.time_s, Severity::Info, "EEG source delivering again");
    } else {
      s_.tell.say(cycle.time_s, Severity::Error, "EEG source: " + out.fault);
      faults_.push_back({{"t", cycle.time_s}, {"fault", out.fault}});
    }
    fault_logged_ = out.fault;
  }
  cycle.eeg_sample = cycle.record.eeg_sample = acquisition_->firstSampleAtOrAfter(cycle.host_s);
}

void EegAcquisitionStage::stop(Cycle& cycle, const std::string&) {
  toSource(cycle);
  if (acquisition_->mode() == bci::Acquisition::Mode::Live) {
    // The samples taken up to a tenth of a second from now, so the last flashes' EEG and
    // photodiode edges are in the recording.
    const std::int64_t wanted = acquisition_->firstSampleAtOrAfter(bci::hostSeconds() + 0.1);
    const double give_up = bci::hostSeconds() + 1.0;
    take(cycle);
    while (next_sample_ < wanted && bci::hostSeconds() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      take(cycle);
    }
  }
  acquisition_->stop();
}

std::string EegAcquisitionStage::sourceLine() const {
  std::string line;
  acquisition_->withSource([&](bci::EegSource& source) { line = source.describe(); });
  return line;
}

void EegAcquisitionStage::report(nlohmann::json& summary) const {
  summary["timing"]["lost_samples"] = acquisition_->lostSamples();
  const bci::ClockReport clock = acquisition_->clockReport();
  summary["timing"]["clock_drift_ppm"] = clock.drift_ppm;
  summary["timing"]["clock_drift_uncertainty_ppm"] = clock.drift_uncertainty_ppm;
  summary["timing"]["clock_drift_reliable"] = clock.drift_reliable;
  summary["timing"]["clock_jitter_ms"] = clock.jitter_s * 1000.0;
  summary["timing"]["eeg_stalls"] = {{"count", stalls_.count},
                                     {"longest_s", stalls_.longest_s},
                                     {"samples", stalls_.samples},
                                     {"uncertain_flashes", stalls_.uncertain_flashes}};
  summary["eeg"]["repeated_samples"] = acquisition_->repeatedSamples();
  summary["eeg"]["lost_samples"] = acquisition_->lostSamples();
  summary["eeg"]["source_markers"] = source_markers_;
  summary["eeg"]["source"] = sourceLine();
  // Every fault the source had (an end, a silence, a lost stream), when it began.
  summary["eeg"]["faults"] = faults_;
  acquisition_->withSource([&](bci::EegSource& source) {
    if (const std::string impedance = source.impedance(); !impedance.empty())
      summary["eeg"]["impedance"] = impedance;
  });
}

}  // namespace arbci::session
