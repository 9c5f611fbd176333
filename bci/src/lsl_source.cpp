#include "arbci/bci/lsl_source.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include <chrono>
#include <thread>

#include "arbci/bci/lsl/inlet.h"
#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/bci/units.h"

namespace arbci::bci {
namespace {

std::string describeStreams(const std::vector<lsl::StreamInfo>& streams) {
  std::string text;
  for (const auto& s : streams)
    text += (text.empty() ? "" : "; ") + s.name + " (type " + s.type + ", " +
            std::to_string(s.channel_count) + " channels, source_id \"" + s.source_id + "\", on " +
            s.hostname + ")";
  return text;
}

}  // namespace

LslSource::LslSource(const LslSourceSettings& settings) : settings_(settings) {
  const std::string query = lsl::buildQuery(settings.config.session_id, settings.name,
                                            settings.type, settings.source_id, settings.host);
  std::string wanted;
  for (const auto& [field, value] : {std::pair<std::string, std::string>{"name", settings.name},
                                     {"type", settings.type},
                                     {"source_id", settings.source_id},
                                     {"host", settings.host}}) {
    if (!value.empty()) wanted += (wanted.empty() ? "" : " ") + field + " \"" + value + "\"";
  }
  // Returns shortly after the first answer (the others on the network answer within the grace).
  auto found = lsl::resolveStreams(settings.config, query, settings.resolve_timeout_s, 1);
  if (found.empty()) {
    char timeout[32];
    std::snprintf(timeout, sizeof timeout, "%.1f", settings.resolve_timeout_s);
    throw lsl::LslError("no LSL stream with " + wanted + " answered within " + timeout + " s (" +
                        settings.config.describe() +
                        "). Is the amplifier's LSL app streaming? "
                        "`arbci eeg streams` lists the streams this machine can see");
  }
  if (found.size() > 1)
    throw lsl::LslError(std::to_string(found.size()) + " LSL streams match " + wanted + ": " +
                        describeStreams(found) +
                        ". Choose one by eeg.lsl.source_id (or eeg.lsl.host, or eeg.lsl.name "
                        "where the names differ)");
  const lsl::StreamInfo& stream = found.front();
  if (stream.channel_format == lsl::ChannelFormat::String)
    throw lsl::LslError("LSL stream \"" + stream.name + "\" carries strings, not EEG samples");
  if (stream.nominal_srate <= 0)
    throw lsl::LslError("LSL stream \"" + stream.name +
                        "\" has no regular sampling rate; EEG needs one");
  if (settings.expected_rate_hz > 0 &&
      std::abs(stream.nominal_srate - settings.expected_rate_hz) > 1e-6)
    throw lsl::LslError("LSL stream \"" + stream.name + "\" runs at " +
                        std::to_string(stream.nominal_srate) + " Hz but the session expects " +
                        std::to_string(settings.expected_rate_hz) +
                        " Hz (eeg.rate_hz). ARBCI does not resample a live stream: set eeg.rate_hz "
                        "to the amplifier's rate");
  inlet_ = std::make_unique<lsl::Inlet>(stream, settings.config);
  if (settings.require_samples) {
    const double deadline = lsl::localClock() + settings.resolve_timeout_s;
    while (inlet_->status().received == 0 && lsl::localClock() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (inlet_->status().received == 0) {
      char timeout[32];
      std::snprintf(timeout, sizeof timeout, "%.1f", settings.resolve_timeout_s);
      throw lsl::LslError("LSL stream \"" + stream.name + "\" on " + stream.hostname +
                          " answered but sent no sample within " + timeout +
                          " s: is the amplifier acquiring?");
    }
  }
  const lsl::StreamInfo& full = inlet_->info();
  info_.rate_hz = full.nominal_srate;
  info_.channels = full.channelLabels();
  info_.block_size = std::max(1, settings.block_size);
  for (int c = 0; c < full.channel_count; ++c)
    scale_.push_back(
        c < static_cast<int>(full.channels.size()) ? microvoltsPer(full.channels[c].unit) : 1.0);
  std::vector<std::string> units;
  for (const auto& channel : full.channels) units.push_back(channel.unit);
  unit_note_ = nonVoltageNote(info_.channels, units);
  name_ = full.name;
  host_ = full.hostname;
  for (size_t c = 0; c < full.channels.size() && c < info_.channels.size(); ++c) {
    if (full.channels[c].impedance.empty()) continue;
    impedance_ +=
        (impedance_.empty() ? "" : ", ") + info_.channels[c] + " " + full.channels[c].impedance;
  }
  if (!impedance_.empty())
    impedance_ +=
        " (the stream's metadata, as its app measured them when it started; LSL "
        "states no unit)";
  pending_ = Block(0, info_.channelCount(), 0);
}

LslSource::~LslSource() = default;

void LslSource::flush(std::vector<Block>& out) {
  if (pending_.samples == 0) return;
  Block block(pending_.first_sample, pending_.channels, pending_.samples);
  // pending_ is sample-major while it fills; blocks are channel-major.
  for (int s = 0; s < pending_.samples; ++s)
    for (int c = 0; c < pending_.channels; ++c)
      block.at(c, s) = pending_.data[static_cast<size_t>(s) * pending_.channels + c];
  const lsl::InletStatus status = inlet_->status();
  if (status.clock_known) block.taken_host_s = last_timestamp_ + status.clock_offset_s;
  out.push_back(std::move(block));
  pending_ = Block(next_index_, info_.channelCount(), 0);
  pending_.data.reserve(static_cast<size_t>(info_.block_size) * info_.channelCount());
}

std::vector<Block> LslSource::poll(int max_blocks) {
  std::vector<Block> out;
  // Until the first time-correction estimate (about 0.6 s), the samples wait in the inlet: a
  // block stamped by its arrival would bend the clock model that the exact stamps then follow.
  if (!inlet_->status().clock_known) return out;
  std::vector<lsl::Sample> samples;
  inlet_->pull(samples, static_cast<size_t>(max_blocks) * info_.block_size);
  const lsl::SampleCodec& codec = inlet_->codec();
  for (const auto& s : samples) {
    if (s.connection != connection_) {
      if (connection_ != 0) {
        // The outlet was away: the samples it would have sent meanwhile are a gap.
        const auto missing = std::llround((s.timestamp - last_timestamp_) * info_.rate_hz) - 1;
        flush(out);
        if (missing > 0) {
          next_index_ += missing;
          gap_samples_ += missing;
          pending_.first_sample = next_index_;
        }
      }
      connection_ = s.connection;
    }
    for (int c = 0; c < info_.channelCount(); ++c)
      pending_.data.push_back(static_cast<float>(codec.value(s, c) * scale_[c]));
    ++pending_.samples;
    ++next_index_;
    last_timestamp_ = s.timestamp;
    if (pending_.samples == info_.block_size) {
      rate_history_.emplace_back(next_index_, last_timestamp_);
      while (rate_history_.size() > 2 && last_timestamp_ - rate_history_.front().second > 10.0)
        rate_history_.pop_front();
      flush(out);
    }
  }
  return out;
}

std::string LslSource::fault() const {
  const lsl::InletStatus status = inlet_->status();
  if (status.connected) return {};
  return "LSL stream \"" + name_ + "\" " + (status.fault.empty() ? "not connected" : status.fault) +
         "; reconnecting when it returns";
}

std::string LslSource::describe() const {
  const lsl::InletStatus status = inlet_->status();
  double measured = std::numeric_limits<double>::quiet_NaN();
  if (rate_history_.size() >= 2) {
    const auto& [s0, t0] = rate_history_.front();
    const auto& [s1, t1] = rate_history_.back();
    if (t1 > t0) measured = static_cast<double>(s1 - s0) / (t1 - t0);
  }
  char text[512];
  std::snprintf(text, sizeof text,
                "LSL \"%s\" on %s: %.6g Hz nominal, %.3f Hz measured; clock offset %+.3f ms "
                "(round trip %.3f ms); %lld samples lost to gaps%s",
                name_.c_str(), inlet_->endpoint().c_str(), info_.rate_hz, measured,
                status.clock_known ? status.clock_offset_s * 1e3 : 0.0,
                status.clock_known ? status.clock_rtt_s * 1e3 : 0.0,
                static_cast<long long>(gap_samples_),
                status.clock_known ? "" : " (clock not yet estimated)");
  return unit_note_.empty() ? std::string(text) : std::string(text) + "; " + unit_note_;
}

std::vector<Annotation> LslSource::takeAnnotations() {
  if (unit_note_.empty() || unit_note_taken_ || next_index_ == 0) return {};
  unit_note_taken_ = true;
  return {Annotation{0, unit_note_, 0}};
}

}  // namespace arbci::bci
