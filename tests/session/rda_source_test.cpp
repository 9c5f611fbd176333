// The "rda" EEG source against a small RDA server written here from BrainProducts' description of
// Remote Data Access (the 24-byte header with the RDA GUID, the start message with the channel
// count, sampling interval, resolutions and names, 32-bit data messages with block numbers,
// the stop message, markers inside data messages), on 127.0.0.1 only: the samples arrive with
// their names, rate and resolution; a lost block is a gap in the sample numbers (which the
// acquisition fills and counts); markers become annotations on their samples; a stream that
// stops and starts again, or whose server goes and comes back, is a fault while it is away and
// goes on after a gap; a server at another rate, one on the 16-bit port, one that is not RDA and
// one that restarts with other channels are refused or reported, each with its reason.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "arbci/bci/acquisition.h"
#include "arbci/session/eeg_sources.h"

namespace arbci::session {
namespace {

constexpr std::uint8_t kGuid[16] = {0x8e, 0x45, 0x58, 0x43, 0x96, 0xc9, 0x86, 0x4c,
                                    0xaf, 0x4a, 0x98, 0xbb, 0xf6, 0xc9, 0x14, 0x50};

template <class T>
void put(std::vector<std::uint8_t>& out, T value) {
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(&value);
  out.insert(out.end(), bytes, bytes + sizeof value);
}

std::vector<std::uint8_t> message(std::uint32_t type, const std::vector<std::uint8_t>& body,
                                  bool rda = true) {
  std::vector<std::uint8_t> out(kGuid, kGuid + 16);
  if (!rda) out.assign(16, 0x42);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(24 + body.size()));
  put<std::uint32_t>(out, type);
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

std::vector<std::uint8_t> startMessage(const std::vector<std::string>& names, double rate_hz,
                                       double resolution) {
  std::vector<std::uint8_t> body;
  put<std::uint32_t>(body, static_cast<std::uint32_t>(names.size()));
  put<double>(body, 1e6 / rate_hz);
  for (size_t c = 0; c < names.size(); ++c) put<double>(body, resolution);
  for (const std::string& name : names) {
    body.insert(body.end(), name.begin(), name.end());
    body.push_back(0);
  }
  return message(1, body);
}

struct Marker {
  std::uint32_t position = 0, points = 1;
  std::string type, description;
};

// `points` samples of every channel from `first`: channel c, sample s has the raw value
// (first + s) * 10 + c; then the markers.
std::vector<std::uint8_t> dataMessage(std::uint32_t block, std::uint32_t points, int channels,
                                      std::int64_t first, const std::vector<Marker>& markers = {},
                                      std::uint32_t type = 4) {
  std::vector<std::uint8_t> body;
  put<std::uint32_t>(body, block);
  put<std::uint32_t>(body, points);
  put<std::uint32_t>(body, static_cast<std::uint32_t>(markers.size()));
  for (std::uint32_t s = 0; s < points; ++s)
    for (int c = 0; c < channels; ++c) {
      if (type == 2)
        put<std::int16_t>(body, static_cast<std::int16_t>(s));
      else
        put<float>(body, static_cast<float>((first + s) * 10 + c));
    }
  for (const Marker& m : markers) {
    put<std::uint32_t>(
        body, static_cast<std::uint32_t>(16 + m.type.size() + 1 + m.description.size() + 1));
    put<std::uint32_t>(body, m.position);
    put<std::uint32_t>(body, m.points);
    put<std::int32_t>(body, -1);  // all channels
    body.insert(body.end(), m.type.begin(), m.type.end());
    body.push_back(0);
    body.insert(body.end(), m.description.begin(), m.description.end());
    body.push_back(0);
  }
  return message(type, body);
}

// What the server does next: send a message, pause, or close the connection and take the next.
struct Step {
  Step(std::vector<std::uint8_t> m) : bytes(std::move(m)) {}  // NOLINT: a message is a step
  static Step pause(int ms) {
    Step s({});
    s.pause_ms = ms;
    return s;
  }
  static Step reconnect() {
    Step s({});
    s.close_and_accept = true;
    return s;
  }
  std::vector<std::uint8_t> bytes;
  int pause_ms = 0;
  bool close_and_accept = false;
};

// A server on 127.0.0.1 (a free port) that runs `steps` with its client, then keeps the
// connection open until destroyed.
class RdaServer {
 public:
  explicit RdaServer(std::vector<Step> steps) : steps_(std::move(steps)) {
    listen_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(listen_, reinterpret_cast<sockaddr*>(&address), sizeof address);
    socklen_t length = sizeof address;
    ::getsockname(listen_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    ::listen(listen_, 1);
    thread_ = std::thread([this] {
      client_ = ::accept(listen_, nullptr, nullptr);
      for (const Step& step : steps_) {
        if (step.close_and_accept) {
          ::close(client_);
          client_ = ::accept(listen_, nullptr, nullptr);
          if (client_ < 0) return;
        }
        if (step.pause_ms > 0)
          std::this_thread::sleep_for(std::chrono::milliseconds(step.pause_ms));
        if (!step.bytes.empty())
          ::send(client_, step.bytes.data(), step.bytes.size(), MSG_NOSIGNAL);
      }
    });
  }
  ~RdaServer() {
    ::shutdown(listen_, SHUT_RDWR);
    thread_.join();
    if (client_ >= 0) ::close(client_);
    ::close(listen_);
  }
  int port() const { return port_; }

 private:
  std::vector<Step> steps_;
  int listen_ = -1, client_ = -1, port_ = 0;
  std::thread thread_;
};

struct Opened {
  EegSettings eeg;
  nlohmann::json own;
  std::unique_ptr<bci::EegSource> source;
};

Opened openRda(int port, double rate_hz = 256.0) {
  Opened o;
  o.eeg.source = "rda";
  o.eeg.rate_hz = rate_hz;
  o.eeg.block_size = 16;
  o.own = {{"host", "127.0.0.1"}, {"port", port}, {"connect_timeout_s", 5.0}};
  const bci::lsl::LslConfig lsl;
  const std::string file = "rda_test.json";
  o.source = eegSources().at("rda").make.make(
      {o.eeg, o.own, lsl, std::make_shared<bci::UnboundedClock>(), file});
  return o;
}

// Polls until `samples` samples, or (`until_fault`) a fault and nothing left to take (at most
// 10 s, on a loaded machine).
std::vector<bci::Block> pollSamples(bci::EegSource& source, std::int64_t samples,
                                    bool until_fault = true) {
  std::vector<bci::Block> blocks;
  std::int64_t got = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (got < samples && std::chrono::steady_clock::now() < give_up) {
    const bool faulty = until_fault && !source.fault().empty();
    const std::vector<bci::Block> taken = source.poll(64);
    for (const bci::Block& b : taken) {
      got += b.samples;
      blocks.push_back(b);
    }
    if (faulty && taken.empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return blocks;
}

const std::vector<std::string> kNames = {"Fz", "Cz", "Pz", "Oz"};

TEST(RdaSource, TheServersSamplesArriveWithTheirNamesRateAndResolution) {
  std::vector<Step> messages = {startMessage(kNames, 500.0, 0.1)};
  for (std::uint32_t b = 0; b < 10; ++b) messages.push_back(dataMessage(b, 20, 4, b * 20));
  RdaServer server(messages);
  Opened o = openRda(server.port(), 500.0);
  EXPECT_EQ(o.source->info().channels, kNames);
  EXPECT_DOUBLE_EQ(o.source->info().rate_hz, 500.0);
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 192);
  ASSERT_EQ(blocks.size(), 12u);  // 200 samples in blocks of 16
  std::int64_t next = 0;
  for (const bci::Block& b : blocks) {
    EXPECT_EQ(b.first_sample, next);
    for (int s = 0; s < b.samples; ++s)
      for (int c = 0; c < 4; ++c)
        EXPECT_FLOAT_EQ(b.at(c, s), static_cast<float>(((next + s) * 10 + c) * 0.1));
    next += b.samples;
  }
  EXPECT_EQ(o.source->fault(), "");
  EXPECT_NE(o.source->describe().find("4 channels at 500 Hz"), std::string::npos);
}

// Block 1 never came: the blocks after it keep their sample numbers, and the gap is left for the
// acquisition to fill and count (as any source's).
TEST(RdaSource, ALostBlockIsAGapInTheSampleNumbers) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 24, 4, 0),
                    dataMessage(2, 24, 4, 48), dataMessage(3, 24, 4, 72)});
  Opened o = openRda(server.port());
  // (How the points are cut into blocks depends on when they are polled; where they lie does not.)
  std::vector<std::int64_t> delivered;
  for (const bci::Block& b : pollSamples(*o.source, 72))
    for (int s = 0; s < b.samples; ++s) {
      delivered.push_back(b.first_sample + s);
      EXPECT_FLOAT_EQ(b.at(3, s), static_cast<float>((b.first_sample + s) * 10 + 3));
    }
  std::vector<std::int64_t> expected;
  for (std::int64_t s = 0; s < 96; ++s)
    if (s < 24 || s >= 48) expected.push_back(s);
  EXPECT_EQ(delivered, expected);
  EXPECT_NE(o.source->describe().find("1 block(s) lost"), std::string::npos)
      << o.source->describe();

  // Through the acquisition: zeros in the gap, counted and reported as a loss.
  RdaServer again({startMessage(kNames, 256.0, 1.0), dataMessage(0, 24, 4, 0),
                   dataMessage(2, 24, 4, 48), dataMessage(3, 24, 4, 72)});
  Opened live = openRda(again.port());
  bci::Acquisition acquisition(std::move(live.source), std::make_shared<bci::UnboundedClock>(),
                               bci::Acquisition::Mode::Live);
  acquisition.start();
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (acquisition.lostSamples() == 0 && std::chrono::steady_clock::now() < give_up) {
    acquisition.take();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(acquisition.lostSamples(), 24);
  const std::vector<bci::SampleLoss> losses = acquisition.takeLosses();
  ASSERT_EQ(losses.size(), 1u);
  EXPECT_EQ(losses[0].first_sample, 24);
  EXPECT_EQ(losses[0].samples, 24);
}

// Recorder's markers (a trigger box's Stimulus and Response TTLs, sent inside the data blocks)
// become annotations "<type>/<description>" on the sample they mark.
TEST(RdaSource, MarkersBecomeAnnotationsOnTheirSamples) {
  RdaServer server(
      {startMessage(kNames, 256.0, 1.0), dataMessage(0, 20, 4, 0),
       dataMessage(1, 20, 4, 20, {{3, 1, "Stimulus", "S  1"}}),
       dataMessage(2, 20, 4, 40, {{0, 1, "Response", "R  8"}, {19, 5, "Comment", "x"}})});
  Opened o = openRda(server.port());
  pollSamples(*o.source, 48);
  std::vector<bci::Annotation> markers;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (markers.size() < 3 && std::chrono::steady_clock::now() < give_up) {
    for (bci::Annotation& a : o.source->takeAnnotations()) markers.push_back(std::move(a));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(markers.size(), 3u);
  EXPECT_EQ(markers[0].sample, 23);
  EXPECT_EQ(markers[0].text, "Stimulus/S  1");
  EXPECT_EQ(markers[1].sample, 40);
  EXPECT_EQ(markers[1].text, "Response/R  8");
  EXPECT_EQ(markers[2].sample, 59);
  EXPECT_EQ(markers[2].duration_samples, 5);
  EXPECT_TRUE(o.source->takeAnnotations().empty());  // each once
}

// Waits (at most 10 s) until the source's fault satisfies `wanted`.
template <class Wanted>
std::string faultWhen(bci::EegSource& source, Wanted wanted) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  std::string fault = source.fault();
  while (!wanted(fault) && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    fault = source.fault();
  }
  return fault;
}

// Recorder stops (or switches to impedance mode) and starts again: a fault while it is away,
// then the data go on after a gap at least as long as the time away (here 0.4 s).
TEST(RdaSource, AStreamThatStopsAndStartsAgainGoesOnAfterAGap) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), message(3, {}),
                    Step::pause(400), startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0),
                    dataMessage(1, 16, 4, 16)});
  Opened o = openRda(server.port());
  const std::string stopped = faultWhen(*o.source, [](const std::string& f) { return !f.empty(); });
  EXPECT_NE(stopped.find("stopped the stream"), std::string::npos) << stopped;
  EXPECT_NE(stopped.find("going on when it starts again"), std::string::npos) << stopped;
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 48, false);
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[0].first_sample, 0);
  EXPECT_GE(blocks[1].first_sample, 16 + static_cast<std::int64_t>(0.4 * 256) - 16);
  EXPECT_EQ(blocks[2].first_sample, blocks[1].first_sample + 16);  // the new counter is no loss
  EXPECT_EQ(faultWhen(*o.source, [](const std::string& f) { return f.empty(); }), "");
  EXPECT_NE(o.source->describe().find("1 restart(s)"), std::string::npos) << o.source->describe();
  // The counter started again at 0: the host clock measured the time away.
  EXPECT_NE(o.source->describe().find("0 resumption(s) counted from the block numbers, 1 from the "
                                      "host clock"),
            std::string::npos)
      << o.source->describe();
}

// Block numbers that go on after a stop count the time away exactly: blocks 1-6 (16 points each)
// were taken while the stream was stopped for about 0.4 s, so block 7 starts on sample 112
// whatever the host clock says.
TEST(RdaSource, AStopWhoseBlockNumbersGoOnIsAGapOfExactlyTheBlocksMissed) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), message(3, {}),
                    Step::pause(400), startMessage(kNames, 256.0, 1.0), dataMessage(7, 16, 4, 112),
                    dataMessage(8, 16, 4, 128)});
  Opened o = openRda(server.port());
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 48, false);
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[1].first_sample, 112);
  EXPECT_FLOAT_EQ(blocks[1].at(0, 0), 1120.0f);
  EXPECT_EQ(blocks[2].first_sample, 128);
  EXPECT_NE(o.source->describe().find("96 samples lost to gaps (1 resumption(s) counted from the "
                                      "block numbers, 0 from the host clock)"),
            std::string::npos)
      << o.source->describe();
}

// Data after a stop with no start message: nothing confirms its channels, so it is left out, a
// fault while it lasts and a note in the recording; the next start goes on, the blocks left out
// counted in the gap by their numbers.
TEST(RdaSource, DataAfterAStopWithoutAStartIsLeftOutAsAFaultWithANote) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), message(3, {}),
                    Step::pause(100), dataMessage(1, 16, 4, 16), dataMessage(2, 16, 4, 32),
                    Step::pause(400), startMessage(kNames, 256.0, 1.0), dataMessage(3, 16, 4, 48)});
  Opened o = openRda(server.port());
  const std::string fault = faultWhen(*o.source, [](const std::string& f) {
    return f.find("without a new start message") != std::string::npos;
  });
  EXPECT_NE(fault.find("left out until the stream starts again"), std::string::npos) << fault;
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 32, false);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[1].first_sample, 48);
  EXPECT_FLOAT_EQ(blocks[1].at(2, 0), 482.0f);
  EXPECT_EQ(faultWhen(*o.source, [](const std::string& f) { return f.empty(); }), "");
  const std::vector<bci::Annotation> notes = o.source->takeAnnotations();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].sample, 16);
  EXPECT_NE(notes[0].text.find("without a start message"), std::string::npos) << notes[0].text;
  EXPECT_NE(o.source->describe().find("2 block(s) after a stop without a start left out"),
            std::string::npos)
      << o.source->describe();
}

// The server goes away (Recorder closed) and comes back 0.4 s later: the client reconnects by
// itself, and the time away is a gap.
TEST(RdaSource, AServerThatGoesAndComesBackIsReconnected) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), Step::reconnect(),
                    Step::pause(400), startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0)});
  Opened o = openRda(server.port());
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 32, false);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_GE(blocks[1].first_sample, 16 + static_cast<std::int64_t>(0.4 * 256) - 16);
  EXPECT_EQ(faultWhen(*o.source, [](const std::string& f) { return f.empty(); }), "");
}

// A restart with other channels cannot go on in the same recording: a fault that says so.
TEST(RdaSource, ARestartWithOtherChannelsIsAFaultThatSaysSo) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), message(3, {}),
                    startMessage({"Fz", "Cz"}, 256.0, 1.0)});
  Opened o = openRda(server.port());
  const std::string fault = faultWhen(*o.source, [](const std::string& f) {
    return f.find("other channels") != std::string::npos;
  });
  EXPECT_NE(fault.find("started again with other channels or another rate"), std::string::npos)
      << fault;
}

TEST(RdaSource, WhatCannotBeReadIsRefusedWithItsReason) {
  auto refusal = [](std::vector<Step> messages, double rate = 256.0) {
    RdaServer server(std::move(messages));
    try {
      openRda(server.port(), rate);
    } catch (const SessionConfigError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  const std::string rate = refusal({startMessage(kNames, 500.0, 0.1)});
  EXPECT_NE(rate.find("runs at 500 Hz, the session at 256 Hz"), std::string::npos) << rate;
  EXPECT_NE(rate.find("eeg.source = \"rda\""), std::string::npos) << rate;
  // The 16-bit port sends the same start message; its first data message tells.
  const std::string sixteen =
      refusal({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0, {}, 2)});
  EXPECT_NE(sixteen.find("sends 16-bit data"), std::string::npos) << sixteen;
  EXPECT_NE(sixteen.find("set eeg.rda.port to its 32-bit port, 51244"), std::string::npos)
      << sixteen;
  const std::string other = refusal({message(1, std::vector<std::uint8_t>(12, 0), false)});
  EXPECT_NE(other.find("does not speak RDA"), std::string::npos) << other;
  // Nobody listening: the port of a server that has gone.
  int gone = 0;
  {
    RdaServer server({});
    gone = server.port();
  }
  const std::string refused = [&] {
    try {
      openRda(gone);
    } catch (const SessionConfigError& error) {
      return std::string(error.what());
    }
    return std::string();
  }();
  EXPECT_NE(refused.find("cannot connect to the RDA server at 127.0.0.1:"), std::string::npos)
      << refused;
}

}  // namespace
}  // namespace arbci::session
