// `arbci eeg streams` and `arbci eeg stream FILE`: the Lab Streaming Layer from the command
// line. `streams` lists what this machine can see; `stream` plays a recording as an LSL outlet in
// real time (its events on a Markers outlet beside it): a stand-in amplifier for demos and tests.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/settings.h"
#include "arbci/session/settings_schema.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/interrupt.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

struct LslOptions {
  std::string scope;
  std::vector<std::string> peers;
  double timeout_s = 2.0;
  std::string file, name, type;        // type: eeg.lsl.type, what a session looks for
  std::vector<std::string> impedance;  // per channel, into the stream's metadata
  bool wait = false, loop = false;
};

bci::lsl::LslConfig configOf(const LslOptions& o) {
  bci::lsl::LslConfig c;
  try {
    c = bci::lsl::LslConfig::load();
  } catch (const bci::lsl::LslError& e) {
    throw CliError(std::string("the LSL configuration: ") + e.what());
  }
  if (!o.scope.empty()) c.resolve_scope = o.scope;
  c.known_peers.insert(c.known_peers.end(), o.peers.begin(), o.peers.end());
  return c;
}

void addScopeOptions(CLI::App* command, LslOptions& o) {
  schemaOption(*command, "--scope", o.scope, session::sessionKey("lsl.scope"),
               "where to look and serve (machine: 127.0.0.1 only); lsl_api.cfg's: its "
               "ResolveScope ($LSLAPICFG, ./lsl_api.cfg, ~/lsl_api/, /etc/lsl_api/), else site");
  command->add_option("--peer", o.peers, "a host to ask directly (repeatable; adds to KnownPeers)");
}

void listStreams(const LslOptions& o) {
  const bci::lsl::LslConfig config = configOf(o);
  std::cerr << "looking for LSL streams for " << o.timeout_s << " s: " << config.describe() << "\n";
  const auto streams =
      bci::lsl::resolveStreams(config, "session_id='" + config.session_id + "'", o.timeout_s, 0);
  if (streams.empty()) {
    std::cout << "no LSL streams seen\n";
    return;
  }
  std::printf("%-24s %-10s %8s %10s %-9s %-20s %-32s %s\n", "name", "type", "channels", "rate (Hz)",
              "format", "host", "source_id", "address");
  for (const auto& s : streams) {
    const std::string rate = s.nominal_srate > 0 ? std::to_string(s.nominal_srate) : "irregular";
    std::printf("%-24s %-10s %8d %10.10s %-9s %-20s %-32s %s:%d\n", s.name.c_str(), s.type.c_str(),
                s.channel_count, rate.c_str(), bci::lsl::formatName(s.channel_format),
                s.hostname.c_str(), s.source_id.empty() ? "-" : s.source_id.c_str(),
                s.v4address.c_str(), s.v4data_port);
  }
}

std::string markerText(const bci::StimulusEvent& e) {
  return "flash " + std::to_string(e.code) + " " +
         (e.known ? (e.target ? "target" : "nontarget") : "unknown");
}

void streamFile(const LslOptions& o) {
  bci::Recording r;
  try {
    r = bci::readRecording(o.file);
  } catch (const bci::RecordingError& e) {
    throw CliError(e.what());
  }
  const bci::lsl::LslConfig config = configOf(o);
  const std::string name = o.name.empty() ? std::filesystem::path(o.file).stem().string() : o.name;
  bci::lsl::StreamInfo eeg;
  eeg.name = name;
  eeg.type = o.type;
  eeg.channel_count = r.info.channelCount();
  eeg.nominal_srate = r.info.rate_hz;
  eeg.channel_format = bci::lsl::ChannelFormat::Float32;
  eeg.source_id = "arbci-eeg-stream:" + std::filesystem::path(o.file).filename().string();
  if (o.impedance.size() > r.info.channels.size())
    throw CliError("--impedance gives " + std::to_string(o.impedance.size()) + " values for " +
                   std::to_string(r.info.channels.size()) + " channels");
  for (size_t c = 0; c < r.info.channels.size(); ++c)
    eeg.channels.push_back(
        {r.info.channels[c], "microvolts", "EEG", c < o.impedance.size() ? o.impedance[c] : ""});
  bci::lsl::StreamInfo markers;
  markers.name = name + "-Markers";
  markers.type = "Markers";
  markers.channel_count = 1;
  markers.channel_format = bci::lsl::ChannelFormat::String;
  markers.source_id = eeg.source_id + ":markers";
  markers.parameters = bci::layoutParameters(r);  // a recorder's XDF keeps the layout
  std::unique_ptr<bci::lsl::Outlet> eeg_outlet, marker_outlet;
  try {
    eeg_outlet = std::make_unique<bci::lsl::Outlet>(eeg, config);
    marker_outlet = std::make_unique<bci::lsl::Outlet>(markers, config);
  } catch (const bci::lsl::LslError& e) {
    throw CliError(std::string("cannot publish the LSL stream: ") + e.what());
  }
  for (const auto& w : eeg_outlet->warnings()) std::cerr << "warning: " << w << "\n";
  std::cerr << "streaming \"" << name << "\" (" << eeg.channel_count << " channels at "
            << eeg.nominal_srate << " Hz, " << r.seconds() << " s) and \"" << markers.name << "\" ("
            << r.stimuli.size() << " stimuli) from " << o.file << "; " << config.describe() << "\n";
  watchInterrupts();
  if (o.wait) {
    std::cerr << "waiting for a consumer (up to 60 s)...\n";
    for (int i = 0; i < 6000 && eeg_outlet->clients() == 0 && !interruptRequested(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (eeg_outlet->clients() == 0) throw CliError("no consumer connected within 60 s");
  }
  std::printf("streaming t0=%.9f\n", bci::lsl::localClock());
  std::fflush(stdout);
  // Blocks of about 1/32 s, each due when its last sample would have been taken.
  const int block = std::max(1, static_cast<int>(r.info.rate_hz / 32));
  std::vector<float> chunk;
  std::int64_t sent_total = 0, pushed = 0, markers_pushed = 0;  // the last two: what went out
  do {
    const double t0 = bci::lsl::localClock() - static_cast<double>(sent_total) / r.info.rate_hz;
    size_t next_stimulus = 0;
    double next_report = 0;
    for (std::int64_t first = 0; first < r.samples && !interruptRequested(); first += block) {
      const int n = static_cast<int>(std::min<std::int64_t>(block, r.samples - first));
      // Stamped with when its first sample was taken; sent when its last one has been.
      const double stamp = t0 + static_cast<double>(sent_total + first) / r.info.rate_hz;
      const double wait = stamp + n / r.info.rate_hz - bci::lsl::localClock();
      if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
      chunk.resize(static_cast<size_t>(n) * eeg.channel_count);
      for (int s = 0; s < n; ++s)
        for (int c = 0; c < eeg.channel_count; ++c)
          chunk[static_cast<size_t>(s) * eeg.channel_count + c] = r.at(c, first + s);
      eeg_outlet->pushRaw(chunk.data(), n, stamp);
      pushed += n;
      for (; next_stimulus < r.stimuli.size() && r.stimuli[next_stimulus].sample < first + n;
           ++next_stimulus) {
        const auto& e = r.stimuli[next_stimulus];
        marker_outlet->pushStrings(
            {markerText(e)}, t0 + static_cast<double>(sent_total + e.sample) / r.info.rate_hz);
        ++markers_pushed;
      }
      const double at = static_cast<double>(first + n) / r.info.rate_hz;
      if (at >= next_report) {
        std::cerr << "\r" << name << ": " << static_cast<int>(at) << " / "
                  << static_cast<int>(r.seconds()) << " s, " << eeg_outlet->clients()
                  << " consumer(s)   " << std::flush;
        next_report = at + 1.0;
      }
    }
    sent_total += r.samples;
  } while (o.loop && !interruptRequested());
  std::cerr << "\n";
  // What went out, an interrupted stream's too (not the file's length).
  std::printf("streamed %lld samples (%.1f s) and %lld markers%s\n", static_cast<long long>(pushed),
              static_cast<double>(pushed) / r.info.rate_hz, static_cast<long long>(markers_pushed),
              interruptRequested() ? " before it was interrupted" : "");
  std::fflush(stdout);
  // Let the consumers take the last samples before the outlet closes.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
}

}  // namespace

void addEegStreamCommands(CLI::App* eeg, int& exit_code) {
  auto options = std::make_shared<LslOptions>();
  CLI::App* list =
      eeg->add_subcommand("streams",
                          "List the Lab Streaming Layer streams this machine can see (name, type,\n"
                          "channels, rate, host).");
  addScopeOptions(list, *options);
  list->add_option("--timeout", options->timeout_s, "seconds to wait for answers")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 60.0));
  list->callback([options, &exit_code] {
    listStreams(*options);
    exit_code = 0;
  });
  CLI::App* stream = eeg->add_subcommand(
      "stream",
      "Play a recording (BCI2000 .dat, GDF, EDF, BDF, XDF) as an LSL outlet in real time, with "
      "its\n"
      "stimuli as strings (\"flash <code> target|nontarget|unknown\") on a Markers outlet\n"
      "NAME-Markers: a stand-in amplifier for demos and tests. Stops at the file's end.");
  stream->add_option("file", options->file, "the recording")->required()->check(CLI::ExistingFile);
  stream->add_option("--name", options->name, "the stream's name (default: the file's name)");
  schemaOption(*stream, "--type", options->type, bci::lslSourceSchema().at("type"),
               "the stream published: by default what a session looks for");
  stream->add_flag("--wait", options->wait, "start when the first consumer connects (up to 60 s)");
  stream
      ->add_option("--impedance", options->impedance,
                   "each channel's impedance, in order, written into the stream's metadata "
                   "(<desc><channels><channel><impedance>) as an amplifier's app that measures "
                   "them does, e.g. --impedance 5,7,12")
      ->delimiter(',');
  stream->add_flag("--loop", options->loop, "start again at the end, until interrupted");
  addScopeOptions(stream, *options);
  stream->callback([options, &exit_code] {
    streamFile(*options);
    exit_code = interruptRequested() ? 3 : 0;
  });
}

}  // namespace arbci::app
