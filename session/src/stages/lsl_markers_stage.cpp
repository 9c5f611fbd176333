#include "arbci/session/stages/lsl_markers_stage.h"

#include "arbci/bci/sample_clock.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

LslMarkersStage::LslMarkersStage(const LslMarkersSettings& settings, const StageServices& services)
    : settings_(settings), s_(services) {
  bci::lsl::StreamInfo info;
  info.name = settings_.stream;
  info.type = "Markers";
  info.channel_count = 1;
  info.channel_format = bci::lsl::ChannelFormat::String;
  info.source_id = "arbci-session-markers:" + settings_.stream;
  info.parameters = settings_.parameters;
  try {
    outlet_ = std::make_unique<bci::lsl::Outlet>(info, settings_.lsl);
  } catch (const bci::lsl::LslError& e) {
    throw SessionConfigError(settings_.session_file + ": lsl.markers: " + e.what());
  }
  s_.log.write("lsl_markers", 0.0,
               {{"stream", info.name},
                {"port", outlet_->info().v4data_port},
                {"scope", settings_.lsl.describe()}});
}

void LslMarkersStage::publish(const Cycle& cycle, const std::string& text, double host_s) {
  // A run on the simulated clock stamps the instant it is sent (its host instants are not LSL's).
  outlet_->pushStrings({text}, cycle.clock.stepped() ? bci::lsl::localClock() : host_s);
}

void LslMarkersStage::publishNote(const Cycle& cycle, const bci::Annotation& note) {
  // When the sample was taken: its distance from the newest one, on the host clock.
  const double now = bci::hostSeconds();
  publish(cycle, note.text,
          now + (static_cast<double>(note.sample) - cycle.clock.fractionalSampleAt(now)) /
                    settings_.eeg_rate_hz);
}

void LslMarkersStage::step(Cycle& cycle) {
  for (const bci::Annotation& note : cycle.previous.annotations) publishNote(cycle, note);
  const Presentation& shown = cycle.record.presentation;
  for (const Presentation::Onset& onset : shown.onsets) {
    const Flash& f = onset.flash;
    publish(cycle,
            "flash " + std::to_string(f.objects ? f.code : f.code + 100) + " " +
                (f.known ? (f.target ? "target" : "nontarget") : "unknown"),
            shown.host_s);
  }
  if (shown.feedback) publishNote(cycle, {shown.sample, shown.feedback->text(), 0});
}

void LslMarkersStage::stop(Cycle& cycle, const std::string& reason) {
  step(cycle);
  publishNote(cycle, {cycle.clock.sampleAt(cycle.host_s), "Session ended: " + reason, 0});
}

}  // namespace arbci::session
