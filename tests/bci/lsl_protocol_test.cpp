// LSL's configuration file, stream descriptions and sample encoding, checked against what
// liblsl 1.16 writes and expects (its defaults, XML fields and test patterns).
#include <gtest/gtest.h>

#include <cstring>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/sample_codec.h"
#include "arbci/bci/lsl/stream_info.h"

namespace arbci::bci::lsl {
namespace {

TEST(LslConfig, DefaultsAreLiblslsAndTheSiteScopeAsksItsGroups) {
  const LslConfig c;
  EXPECT_EQ(c.multicast_port, 16571);
  EXPECT_EQ(c.base_port, 16572);
  EXPECT_EQ(c.port_range, 32);
  EXPECT_EQ(c.resolve_scope, "site");
  const std::vector<std::string> site{"127.0.0.1", "255.255.255.255", "224.0.0.1", "224.0.0.183",
                                      "239.255.172.215"};
  EXPECT_EQ(c.queryAddresses(), site);
  EXPECT_FALSE(c.machineOnly());
  EXPECT_EQ(c.multicastTtl(), 24);
}

TEST(LslConfig, AFileSetsScopePeersPortsAndSessionAsLiblslReadsThem) {
  const LslConfig c = LslConfig::parse(
      "; a lab's lsl_api.cfg\n[ports]\nBasePort = 17000\nPortRange = 8\nIPv6 = disable\n"
      "[multicast]\nResolveScope = machine\nMachineAddresses = {127.0.0.1, FF31::1}\n"
      "[lab]\nKnownPeers = {amp-pc, 10.0.0.7}\nSessionID = study2\n"
      "[tuning]\nTimeProbeCount = 4\n",
      "test.cfg");
  EXPECT_EQ(c.base_port, 17000);
  EXPECT_EQ(c.port_range, 8);
  EXPECT_EQ(c.queryAddresses(), std::vector<std::string>{"127.0.0.1"});  // IPv6 left out
  EXPECT_EQ(c.known_peers, (std::vector<std::string>{"amp-pc", "10.0.0.7"}));
  EXPECT_EQ(c.session_id, "study2");
  EXPECT_EQ(c.time_probe_count, 4);
  EXPECT_FALSE(c.machineOnly());  // peers are asked too
  EXPECT_EQ(c.multicastTtl(), 0);
  const LslConfig link = LslConfig::parse("[multicast]\nResolveScope = link\n", "link.cfg");
  EXPECT_EQ(link.queryAddresses().size(), 4u);
  EXPECT_EQ(link.multicastTtl(), 1);
}

TEST(LslConfig, AMistakeInTheFileIsNamedWithItsLine) {
  try {
    LslConfig::parse("[multicast]\nResolveScope = planet\n", "bad.cfg");
    FAIL() << "an unknown scope was accepted";
  } catch (const LslError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.cfg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("machine, link, site"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LslConfig::parse("[ports]\nBasePort = 99999\n", "x"), LslError);
  EXPECT_THROW(LslConfig::parse("[lab]\nKnownPeers = amp-pc\n", "x"), LslError);
  EXPECT_THROW(LslConfig::parse("[lab\n", "x"), LslError);
}

StreamInfo exampleStream() {
  StreamInfo s;
  s.name = "ActiChamp-1";
  s.type = "EEG";
  s.channel_count = 3;
  s.nominal_srate = 500;
  s.channel_format = ChannelFormat::Int16;
  s.source_id = "AC-123";
  s.uid = "0b1c2d3e-0000-4000-8000-000000000001";
  s.hostname = "amp-pc";
  s.v4data_port = 16573;
  s.v4service_port = 16572;
  s.created_at = 1234.5;
  s.channels = {
      {"Fz", "microvolts", "EEG", "5"}, {"Cz", "microvolts", "EEG", ""}, {"Pz", "", "", ""}};
  return s;
}

TEST(LslStreamInfo, TheFullDescriptionRoundTripsWithItsChannelLabels) {
  const StreamInfo s = exampleStream();
  const StreamInfo back = StreamInfo::fromXml(s.toXml(true));
  EXPECT_EQ(back.name, s.name);
  EXPECT_EQ(back.channel_format, ChannelFormat::Int16);
  EXPECT_DOUBLE_EQ(back.nominal_srate, 500);
  EXPECT_EQ(back.version, 110);
  EXPECT_EQ(back.v4data_port, 16573);
  EXPECT_EQ(back.channelLabels(), (std::vector<std::string>{"Fz", "Cz", "Pz"}));
  EXPECT_EQ(back.channels[0].impedance, "5");
  EXPECT_EQ(back.channels[1].impedance, "");
  // The short form (discovery replies) has no channels: labels default to Ch1...
  const StreamInfo brief = StreamInfo::fromXml(s.toXml(false));
  EXPECT_EQ(brief.channelLabels(), (std::vector<std::string>{"Ch1", "Ch2", "Ch3"}));
}

TEST(LslStreamInfo, QueriesAreXPathOverTheDescriptionAsLiblslEvaluatesThem) {
  const StreamInfo s = exampleStream();
  EXPECT_TRUE(s.matches(buildQuery("default", "ActiChamp-1", "EEG")));
  EXPECT_TRUE(s.matches("session_id='default' and type='EEG'"));
  EXPECT_FALSE(s.matches(buildQuery("default", "Other", "EEG")));
  EXPECT_FALSE(s.matches(buildQuery("study2", "", "EEG")));
  EXPECT_TRUE(s.matches("starts-with(name,'Acti') and channel_count>2"));
  EXPECT_TRUE(s.matches(""));
  EXPECT_THROW(s.matches("name=='"), LslError);
  EXPECT_THROW(buildQuery("default", "it's", ""), LslError);
}

TEST(LslStreamInfo, AMalformedDescriptionIsRefusedWithTheReason) {
  try {
    StreamInfo::fromXml("<info><name>x</name><channel_count>two</channel_count></info>");
    FAIL();
  } catch (const LslError& e) {
    EXPECT_NE(std::string(e.what()).find("channel_count"), std::string::npos) << e.what();
  }
  EXPECT_THROW(StreamInfo::fromXml("<info><name>"), LslError);
}

TEST(LslSampleCodec, TestPatternsAreLiblsls) {
  // liblsl: value k is (k + offset) with alternating sign; the offset per format.
  const SampleCodec floats(ChannelFormat::Float32, 4);
  const Sample f = floats.testPattern(4);
  EXPECT_DOUBLE_EQ(f.timestamp, 123456.789);
  EXPECT_EQ(floats.value(f, 0), 4.0);
  EXPECT_EQ(floats.value(f, 1), -5.0);
  EXPECT_EQ(floats.value(f, 3), -7.0);
  const SampleCodec shorts(ChannelFormat::Int16, 2);
  EXPECT_EQ(shorts.value(shorts.testPattern(2), 1), -(1 + 2 + 257));
  const SampleCodec doubles(ChannelFormat::Double64, 1);
  EXPECT_EQ(doubles.value(doubles.testPattern(2), 0), 16777219.0);
  const SampleCodec ints(ChannelFormat::Int32, 2);
  EXPECT_EQ(ints.value(ints.testPattern(4), 1), -(1 + 4 + 65537));
  const SampleCodec strings(ChannelFormat::String, 3);
  EXPECT_EQ(strings.testPattern(4).strings, (std::vector<std::string>{"10", "-11", "12"}));
}

TEST(LslSampleCodec, EverySampleFormatRoundTripsThroughTheWireBitForBit) {
  for (ChannelFormat format :
       {ChannelFormat::Float32, ChannelFormat::Double64, ChannelFormat::Int32, ChannelFormat::Int16,
        ChannelFormat::Int8, ChannelFormat::Int64, ChannelFormat::String}) {
    SCOPED_TRACE(formatName(format));
    const SampleCodec codec(format, 5);
    Sample sample = codec.testPattern(4);
    sample.timestamp = 42.125;
    Sample deduced = codec.testPattern(2);
    deduced.deduced = true;
    if (format == ChannelFormat::String)
      deduced.strings[1] = std::string(300, 'x');  // 4-byte length
    std::string wire;
    codec.encode(wire, sample);
    codec.encode(wire, deduced);
    // Tag 2 + timestamp for the first; tag 1 alone for the second.
    EXPECT_EQ(wire[0], 2);
    size_t at = 0;
    const auto read = [&](void* into, size_t n) {
      ASSERT_LE(at + n, wire.size());
      std::memcpy(into, wire.data() + at, n);
      at += n;
    };
    Sample a, b;
    codec.decode(read, false, a);
    codec.decode(read, false, b);
    EXPECT_EQ(at, wire.size());
    EXPECT_TRUE(codec.same(a, sample));
    EXPECT_TRUE(b.deduced);
    EXPECT_EQ(b.raw, deduced.raw);
    EXPECT_EQ(b.strings, deduced.strings);
  }
}

TEST(LslSampleCodec, ValuesSentInTheOtherByteOrderAreTurnedAround) {
  const SampleCodec codec(ChannelFormat::Int32, 1);
  // tag 2, timestamp 1.0 big-endian, value 0x01020304 big-endian.
  const unsigned char wire[] = {2, 0x3f, 0xf0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4};
  size_t at = 0;
  Sample s;
  codec.decode(
      [&](void* into, size_t n) {
        std::memcpy(into, wire + at, n);
        at += n;
      },
      true, s);
  EXPECT_DOUBLE_EQ(s.timestamp, 1.0);
  EXPECT_EQ(codec.value(s, 0), 0x01020304);
}

TEST(LslSampleCodec, ACorruptTagIsRefused) {
  const SampleCodec codec(ChannelFormat::Float32, 1);
  const char wire[] = {7, 0, 0, 0, 0};
  size_t at = 0;
  Sample s;
  EXPECT_THROW(codec.decode(
                   [&](void* into, size_t n) {
                     std::memcpy(into, wire + at, n);
                     at += n;
                   },
                   false, s),
               LslError);
}

}  // namespace
}  // namespace arbci::bci::lsl
