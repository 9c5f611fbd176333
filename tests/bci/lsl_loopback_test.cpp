// ARBCI's LSL outlet and inlet talking over loopback (127.0.0.1 only: the machine scope), in one
// process and in two. Every wait is bounded.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "arbci/bci/lsl/inlet.h"
#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/lsl/resolver.h"
#include "arbci/bci/lsl_source.h"
#include "support/background_process.h"
#include "support/lsl_scope.h"
#include "support/lsl_test_signal.h"

namespace arbci::bci::lsl {
namespace {

std::string uniqueName(const std::string& what) {
  return what + "-" + std::to_string(::getpid()) + "-" +
         ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

StreamInfo eegStream(const std::string& name, int channels, double rate, ChannelFormat format) {
  StreamInfo s;
  s.name = name;
  s.type = "EEG";
  s.channel_count = channels;
  s.nominal_srate = rate;
  s.channel_format = format;
  s.source_id = name + "-source";
  for (int c = 0; c < channels; ++c)
    s.channels.push_back({std::string("E").append(std::to_string(c + 1)), "microvolts", "EEG", ""});
  return s;
}

// Pulls until `count` samples have come or `timeout_s` passed.
std::vector<Sample> pullSamples(Inlet& inlet, size_t count, double timeout_s) {
  std::vector<Sample> got;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (got.size() < count && std::chrono::steady_clock::now() < deadline) {
    if (inlet.pull(got, count - got.size()) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return got;
}

void waitForClient(const Outlet& outlet) {
  for (int i = 0; i < 500 && outlet.clients() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GT(outlet.clients(), 0) << "the inlet never connected";
}

TEST(LslLoopback, AnOutletIsFoundByNameAndTypeOnLoopbackOnly) {
  const std::string name = uniqueName("found");
  Outlet outlet(eegStream(name, 4, 256, ChannelFormat::Float32), test::machineScope());
  EXPECT_TRUE(outlet.warnings().empty()) << outlet.warnings().front();
  const auto found = resolveStreams(test::machineScope(), buildQuery("default", name, "EEG"), 3.0);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].uid, outlet.info().uid);
  EXPECT_EQ(found[0].v4address, "127.0.0.1");
  EXPECT_EQ(found[0].v4data_port, outlet.info().v4data_port);
  EXPECT_TRUE(
      resolveStreams(test::machineScope(), buildQuery("default", name, "Markers"), 0.6).empty());
  // The full description carries the channel labels.
  const StreamInfo full = fetchFullInfo(found[0], 2.0);
  EXPECT_EQ(full.channelLabels(), (std::vector<std::string>{"E1", "E2", "E3", "E4"}));
}

TEST(LslLoopback, EveryFormatArrivesBitIdenticalWithItsTimestamps) {
  for (ChannelFormat format : {ChannelFormat::Float32, ChannelFormat::Double64,
                               ChannelFormat::Int32, ChannelFormat::Int16}) {
    SCOPED_TRACE(formatName(format));
    const std::string name = uniqueName(formatName(format));
    Outlet outlet(eegStream(name, 7, 500, format), test::machineScope());
    const auto found = resolveStreams(test::machineScope(), buildQuery("default", name, ""), 3.0);
    ASSERT_EQ(found.size(), 1u);
    Inlet inlet(found[0], test::machineScope());
    waitForClient(outlet);
    const SampleCodec codec(format, 7);
    std::vector<char> chunk;
    Sample one;
    for (int s = 0; s < 100; ++s)
      for (int c = 0; c < 7; ++c) {
        codec.setValue(one, c, (s * 7 + c) * (c % 2 ? -1 : 1) * 3);
        if (c == 6) chunk.insert(chunk.end(), one.raw.begin(), one.raw.end());
      }
    outlet.pushRaw(chunk.data(), 50, 1000.0);
    outlet.pushRaw(chunk.data() + 50 * codec.rawBytes(), 50, 1000.1);
    const auto got = pullSamples(inlet, 100, 5.0);
    ASSERT_EQ(got.size(), 100u);
    for (int s = 0; s < 100; ++s) {
      EXPECT_EQ(std::vector<char>(chunk.begin() + s * codec.rawBytes(),
                                  chunk.begin() + (s + 1) * codec.rawBytes()),
                got[s].raw);
      EXPECT_NEAR(got[s].timestamp, 1000.0 + s / 500.0, 1e-9);
    }
  }
}

TEST(LslLoopback, TheClockOffsetOnOneMachineIsEstimatedNearZero) {
  const std::string name = uniqueName("clock");
  Outlet outlet(eegStream(name, 1, 100, ChannelFormat::Float32), test::machineScope());
  const auto found = resolveStreams(test::machineScope(), buildQuery("default", name, ""), 3.0);
  ASSERT_EQ(found.size(), 1u);
  Inlet inlet(found[0], test::machineScope());
  InletStatus status;
  for (int i = 0; i < 300 && !(status = inlet.status()).clock_known; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(status.clock_known);
  // Both ends read the same steady clock: the true offset is 0.
  EXPECT_LT(std::abs(status.clock_offset_s), 1e-4);
  EXPECT_LT(status.clock_rtt_s, 0.01);
}

TEST(LslLoopback, StringMarkersArriveWithTheirOwnTimestamps) {
  const std::string name = uniqueName("markers");
  StreamInfo markers;
  markers.name = name;
  markers.type = "Markers";
  markers.channel_count = 1;
  markers.channel_format = ChannelFormat::String;
  Outlet outlet(markers, test::machineScope());
  const auto found =
      resolveStreams(test::machineScope(), buildQuery("default", name, "Markers"), 3.0);
  ASSERT_EQ(found.size(), 1u);
  Inlet inlet(found[0], test::machineScope());
  waitForClient(outlet);
  outlet.pushStrings({"flash 3 target"}, 10.25);
  outlet.pushStrings({std::string(400, 'm')}, 11.5);
  const auto got = pullSamples(inlet, 2, 5.0);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].strings[0], "flash 3 target");
  EXPECT_DOUBLE_EQ(got[0].timestamp, 10.25);
  EXPECT_EQ(got[1].strings[0].size(), 400u);
  EXPECT_DOUBLE_EQ(got[1].timestamp, 11.5);
}

TEST(LslSource, NoStreamIsRefusedWithAMessageNamingItAndTheScope) {
  LslSourceSettings settings;
  settings.name = uniqueName("absent");
  settings.resolve_timeout_s = 0.6;
  settings.config = test::machineScope();
  try {
    LslSource source(settings);
    FAIL() << "a source without a stream was made";
  } catch (const LslError& e) {
    EXPECT_NE(std::string(e.what()).find(settings.name), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("scope machine"), std::string::npos) << e.what();
  }
}

// Two outlets of the same name (two amplifiers of one model): the refusal names their source ids,
// and the source id picks one.
TEST(LslSource, StreamsOfTheSameNameAreToldApartBySourceId) {
  const std::string name = uniqueName("twin");
  StreamInfo first = eegStream(name, 2, 256, ChannelFormat::Float32);
  StreamInfo second = eegStream(name, 3, 256, ChannelFormat::Float32);
  first.source_id = name + "-left";
  second.source_id = name + "-right";
  Outlet a(first, test::machineScope()), b(second, test::machineScope());
  LslSourceSettings settings;
  settings.name = name;
  settings.resolve_timeout_s = 1.0;
  settings.config = test::machineScope();
  settings.require_samples = false;
  try {
    LslSource source(settings);
    FAIL() << "two streams of one name were not refused";
  } catch (const LslError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find(first.source_id), std::string::npos) << text;
    EXPECT_NE(text.find(second.source_id), std::string::npos) << text;
    EXPECT_NE(text.find("eeg.lsl.source_id"), std::string::npos) << text;
  }
  settings.source_id = second.source_id;
  LslSource chosen(settings);
  EXPECT_EQ(chosen.info().channelCount(), 3);
}

// A unicast query to 127.0.0.1:16571 that ARBCI's responder (in another process) takes (the
// kernel hands it to one socket only) is passed on to the outlet port range on 127.0.0.1, where
// every outlet, liblsl's included, answers it to the asker: here a socket in the range stands in
// for a liblsl outlet's unicast server and gets the query as sent. (Called from the test below:
// a plain responder bound by a test running beside it would take the query and pass nothing on.)
void checkPassedOn(const std::string& name) {
  const LslConfig config = test::machineScope();
  arbci::test::BackgroundProcess outlet(
      LSL_OUTLET_HELPER, {name, name + "-src", "2", "256", "1", "0", "1000", "-1", "30"});
  ASSERT_TRUE(outlet.waitForLine("ready", 10.0)) << "the outlet process did not start";
  int other = -1;
  for (int port = config.base_port; port < config.base_port + config.port_range && other < 0;
       ++port) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
      other = fd;
    } else {
      ::close(fd);
    }
  }
  ASSERT_GE(other, 0) << "no free port in the outlet range";
  const int asker = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(config.multicast_port));
  ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  const std::string query = "LSL:shortinfo\r\nname='" + name + "-elsewhere'\r\n12345 q-2\r\n";
  std::string received;
  sockaddr_in from{};
  for (int attempt = 0; attempt < 5 && received.empty(); ++attempt) {
    ::sendto(asker, query.data(), query.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    pollfd watched{other, POLLIN, 0};
    if (::poll(&watched, 1, 400) == 1) {
      char buffer[2048];
      socklen_t length = sizeof from;
      const ssize_t n =
          ::recvfrom(other, buffer, sizeof buffer, 0, reinterpret_cast<sockaddr*>(&from), &length);
      if (n > 0) received.assign(buffer, static_cast<size_t>(n));
    }
  }
  ::close(other);
  ::close(asker);
  EXPECT_EQ(received, query);
  EXPECT_EQ(ntohl(from.sin_addr.s_addr), INADDR_LOOPBACK);  // so replies go to the asker
}

// The discovery port is shared as liblsl shares it: bound on any address. With an ARBCI outlet's
// responder running in another process, a responder bound afterwards as liblsl binds its own
// (0.0.0.0:16571, the address reusable) still receives a unicast query to 127.0.0.1 (Linux hands a
// unicast datagram to the most specific binding, the newest among equals): a 127.0.0.1 binding of
// ARBCI's would have taken every such query from liblsl's outlets.
TEST(LslLoopback, TheDiscoveryPortIsSharedAsLiblslBindsIt) {
  const std::string name = uniqueName("shared");
  arbci::test::BackgroundProcess outlet(
      LSL_OUTLET_HELPER, {name, name + "-src", "2", "256", "1", "0", "1000", "-1", "30"});
  ASSERT_TRUE(outlet.waitForLine("ready", 10.0)) << "the outlet process did not start";
  const int port = test::machineScope().multicast_port;
  auto udp = [](const char* address, int at, bool reuse) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    const int one = 1;
    if (reuse) ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(at));
    ::inet_pton(AF_INET, address, &a.sin_addr);
    EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0) << address << ":" << at;
    return fd;
  };
  const int liblsl_like = udp("0.0.0.0", port, true);
  const int asker = udp("127.0.0.1", 0, false);
  const std::string query = "LSL:shortinfo\r\nname='" + name + "'\r\n12345 query-1\r\n";
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  // Asked a few times: a responder another test process binds meanwhile would be newer still.
  std::string received;
  for (int attempt = 0; attempt < 5 && received.empty(); ++attempt) {
    ::sendto(asker, query.data(), query.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    pollfd watched{liblsl_like, POLLIN, 0};
    if (::poll(&watched, 1, 400) == 1) {
      char buffer[2048];
      const ssize_t n = ::recv(liblsl_like, buffer, sizeof buffer, 0);
      if (n > 0) received.assign(buffer, static_cast<size_t>(n));
    }
  }
  ::close(liblsl_like);
  ::close(asker);
  EXPECT_EQ(received, query) << "the query to 127.0.0.1 did not reach a responder bound as "
                                "liblsl's";
  checkPassedOn(name);
}

TEST(LslSource, AStreamThatSendsNothingIsRefusedBeforeTheSession) {
  const std::string name = uniqueName("silent");
  Outlet outlet(eegStream(name, 2, 256, ChannelFormat::Float32), test::machineScope());
  LslSourceSettings settings;
  settings.name = name;
  settings.resolve_timeout_s = 1.0;
  settings.config = test::machineScope();
  try {
    LslSource source(settings);
    FAIL();
  } catch (const LslError& e) {
    EXPECT_NE(std::string(e.what()).find("sent no sample"), std::string::npos) << e.what();
  }
}

TEST(LslSource, AStreamAtAnotherRateThanTheSessionsIsRefused) {
  const std::string name = uniqueName("rate");
  Outlet outlet(eegStream(name, 2, 500, ChannelFormat::Float32), test::machineScope());
  LslSourceSettings settings;
  settings.name = name;
  settings.expected_rate_hz = 256;
  settings.config = test::machineScope();
  settings.require_samples = false;
  try {
    LslSource source(settings);
    FAIL();
  } catch (const LslError& e) {
    EXPECT_NE(std::string(e.what()).find("500"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("eeg.rate_hz"), std::string::npos) << e.what();
  }
}

// Two channels of doubles at 256 Hz, E1 and E2 in these units.
StreamInfo twoChannels(const std::string& name, const std::string& unit1,
                       const std::string& unit2) {
  StreamInfo info = eegStream(name, 2, 256, ChannelFormat::Double64);
  info.channels[0].unit = unit1;
  info.channels[1].unit = unit2;
  return info;
}

// Settings for a source of the stream `name` on this machine, blocks of 4, connected before the
// stream pushes anything.
LslSourceSettings fourSampleBlocksOf(const std::string& name) {
  LslSourceSettings settings;
  settings.name = name;
  settings.block_size = 4;
  settings.config = test::machineScope();
  settings.require_samples = false;  // it pushes once connected
  return settings;
}

// Four samples of two channels pushed once the source is connected, and the block they make.
std::vector<Block> pushFourAndPoll(Outlet& outlet, LslSource& source, const double (&values)[8]) {
  waitForClient(outlet);
  outlet.pushRaw(values, 4, 50.0);
  std::vector<Block> blocks;
  for (int i = 0; i < 200 && blocks.empty(); ++i) {
    blocks = source.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return blocks;
}

// Also: impedances in the stream's metadata (as amplifier apps that measure them write them) are
// reported for the EEG panel, per channel, with the caveat that LSL states no unit.
TEST(LslSource, VoltsAreTurnedIntoMicrovoltsAndBlocksCarryTheLabels) {
  const std::string name = uniqueName("volts");
  StreamInfo info = twoChannels(name, "V", "");
  info.channels[1].impedance = "12.5";
  Outlet outlet(info, test::machineScope());
  LslSource source(fourSampleBlocksOf(name));
  EXPECT_EQ(source.info().channels, (std::vector<std::string>{"E1", "E2"}));
  const std::vector<Block> blocks =
      pushFourAndPoll(outlet, source, {1e-5, 3.0, 2e-5, 4.0, 3e-5, 5.0, 4e-5, 6.0});
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_NEAR(blocks[0].at(0, 2), 30.0, 1e-4);  // 3e-5 V
  EXPECT_FLOAT_EQ(blocks[0].at(1, 3), 6.0);
  EXPECT_TRUE(source.fault().empty());
  EXPECT_NE(source.describe().find(name), std::string::npos);
  EXPECT_EQ(source.impedance().rfind("E2 12.5 (the stream's metadata", 0), 0u)
      << source.impedance();
}

// A channel whose stated unit is no voltage ("counts") is kept as it is, and said so: in the
// Session panel's source line and, once, in the recording's annotations.
TEST(LslSource, AChannelNotInVoltsIsKeptAsItIsAndSaidSo) {
  const std::string name = uniqueName("counts");
  Outlet outlet(twoChannels(name, "microvolts", "counts"), test::machineScope());
  LslSource source(fourSampleBlocksOf(name));
  EXPECT_TRUE(source.takeAnnotations().empty());  // nothing delivered yet
  const std::vector<Block> blocks =
      pushFourAndPoll(outlet, source, {1.0, 100.0, 2.0, 200.0, 3.0, 300.0, 4.0, 400.0});
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_FLOAT_EQ(blocks[0].at(1, 2), 300.0f);
  const std::string said = "channel(s) E2 (\"counts\") are not in a voltage unit";
  EXPECT_NE(source.describe().find(said), std::string::npos) << source.describe();
  const std::vector<Annotation> notes = source.takeAnnotations();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].text.rfind(said, 0), 0u) << notes[0].text;
  EXPECT_TRUE(source.takeAnnotations().empty());  // once
}

// The check: a second process streams 64 channels at 2048 Hz for 10 minutes of
// simulated time (at 100 times real time).
TEST(LslTwoProcesses, TenMinutesOf64ChannelsAt2048HzArriveCompleteAndBitIdentical) {
  const std::string name = uniqueName("two");
  constexpr int kChannels = 64;
  constexpr double kRate = 2048;
  constexpr std::int64_t kSamples = static_cast<std::int64_t>(600 * kRate);
  arbci::test::BackgroundProcess outlet(
      LSL_OUTLET_HELPER, {name, name + "-src", std::to_string(kChannels), "2048", "100", "0",
                          std::to_string(kSamples), "-1", "60"});
  const auto ready = outlet.waitForLine("ready", 10.0);
  ASSERT_TRUE(ready) << "the outlet process did not start";
  const double t0 = std::stod(ready->substr(ready->find("t0=") + 3));
  LslSourceSettings settings;
  settings.name = name;
  settings.expected_rate_hz = kRate;
  settings.block_size = 64;
  settings.config = test::machineScope();
  LslSource source(settings);
  std::int64_t next = 0, wrong_values = 0, wrong_stamps = 0;
  double worst_stamp_error = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (next < kSamples && std::chrono::steady_clock::now() < deadline) {
    const auto blocks = source.poll(256);
    if (blocks.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    for (const Block& b : blocks) {
      ASSERT_EQ(b.first_sample, next);
      for (int s = 0; s < b.samples; ++s)
        for (int c = 0; c < kChannels; ++c)
          wrong_values += b.at(c, s) != arbci::test::lslTestValue(next + s, c);
      // The block's last sample, moved onto our clock, against the sender's stamp for it.
      if (!std::isnan(b.taken_host_s)) {
        const double error = std::abs(b.taken_host_s - (t0 + (b.endSample() - 1) / kRate));
        worst_stamp_error = std::max(worst_stamp_error, error);
        wrong_stamps += error > 1e-4;
      }
      next = b.endSample();
    }
  }
  EXPECT_EQ(next, kSamples);
  EXPECT_EQ(wrong_values, 0);
  EXPECT_EQ(wrong_stamps, 0) << "worst " << worst_stamp_error * 1e3 << " ms";
  EXPECT_EQ(source.gapSamples(), 0);
  const auto done = outlet.waitForLine("done", 10.0);
  ASSERT_TRUE(done);
  EXPECT_EQ(*done, "done dropped=0");
}

TEST(LslTwoProcesses, AnOutletKilledAndRestartedIsReconnectedAndTheGapCountedExactly) {
  const std::string name = uniqueName("restart");
  constexpr std::int64_t kStopAt = 5000, kResumeAt = 7340, kEnd = 10000;  // whole blocks of 10
  const std::string rate = "1000";
  arbci::test::BackgroundProcess first(
      LSL_OUTLET_HELPER,
      {name, name + "-src", "8", rate, "20", "0", std::to_string(kStopAt), "-1", "60"});
  const auto ready = first.waitForLine("ready", 10.0);
  ASSERT_TRUE(ready);
  const std::string t0 = ready->substr(
      ready->find("t0=") + 3, ready->find(' ', ready->find("t0=")) - ready->find("t0=") - 3);
  LslSourceSettings settings;
  settings.name = name;
  settings.block_size = 10;
  settings.config = test::machineScope();
  LslSource source(settings);
  std::vector<Block> blocks;
  const auto collect = [&](std::int64_t until, double timeout_s) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while ((blocks.empty() || blocks.back().endSample() < until) &&
           std::chrono::steady_clock::now() < deadline) {
      for (auto& b : source.poll(256)) blocks.push_back(std::move(b));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  };
  collect(kStopAt, 20.0);
  ASSERT_FALSE(blocks.empty());
  ASSERT_EQ(blocks.back().endSample(), kStopAt);
  first.kill();
  std::string fault;
  for (int i = 0; i < 300 && (fault = source.fault()).empty(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_NE(fault.find(name), std::string::npos) << "the lost stream was not reported";
  // The same amplifier (source id) comes back, its clock having run on.
  arbci::test::BackgroundProcess second(
      LSL_OUTLET_HELPER, {name, name + "-src", "8", rate, "20", std::to_string(kResumeAt),
                          std::to_string(kEnd), t0, "60"});
  ASSERT_TRUE(second.waitForLine("ready", 10.0));
  collect(kEnd, 20.0);
  ASSERT_FALSE(blocks.empty());
  EXPECT_EQ(blocks.back().endSample(), kEnd);
  EXPECT_EQ(source.gapSamples(), kResumeAt - kStopAt);
  EXPECT_TRUE(source.fault().empty());
  // Every sample sits at its own index on both sides of the gap.
  std::int64_t wrong = 0, checked = 0;
  for (const Block& b : blocks)
    for (int s = 0; s < b.samples; ++s, ++checked)
      for (int c = 0; c < 8; ++c)
        wrong += b.at(c, s) != arbci::test::lslTestValue(b.first_sample + s, c);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(checked, kStopAt + (kEnd - kResumeAt));
}

}  // namespace
}  // namespace arbci::bci::lsl
