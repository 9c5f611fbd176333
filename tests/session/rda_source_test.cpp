// The "rda" EEG source against a small RDA server written here from BrainProducts' description of
// Remote Data Access (the 24-byte header with the RDA GUID, the start message with the channel
// count, sampling interval, resolutions and names, 32-bit data messages with block numbers,
// the stop message), on 127.0.0.1 only: the samples arrive with their names, rate and
// resolution; a lost block is filled with zeros on its samples; a server at another rate, one
// sending 16-bit data, one that is not RDA, and a stream that stops are refused or reported,
// each with its reason.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

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

// `points` samples of every channel from `first`: channel c, sample s has the raw value
// (first + s) * 10 + c.
std::vector<std::uint8_t> dataMessage(std::uint32_t block, std::uint32_t points, int channels,
                                      std::int64_t first) {
  std::vector<std::uint8_t> body;
  put<std::uint32_t>(body, block);
  put<std::uint32_t>(body, points);
  put<std::uint32_t>(body, 0);  // markers
  for (std::uint32_t s = 0; s < points; ++s)
    for (int c = 0; c < channels; ++c) put<float>(body, static_cast<float>((first + s) * 10 + c));
  return message(4, body);
}

// A server on 127.0.0.1 (a free port) that sends `messages` to the first client, then keeps the
// connection open until destroyed.
class RdaServer {
 public:
  explicit RdaServer(std::vector<std::vector<std::uint8_t>> messages)
      : messages_(std::move(messages)) {
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
      for (const auto& m : messages_) ::send(client_, m.data(), m.size(), MSG_NOSIGNAL);
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
  std::vector<std::vector<std::uint8_t>> messages_;
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

// Polls until `samples` samples, or a fault and nothing left to take (at most 10 s, on a loaded
// machine).
std::vector<bci::Block> pollSamples(bci::EegSource& source, std::int64_t samples) {
  std::vector<bci::Block> blocks;
  std::int64_t got = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (got < samples && std::chrono::steady_clock::now() < give_up) {
    const bool faulty = !source.fault().empty();
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
  std::vector<std::vector<std::uint8_t>> messages = {startMessage(kNames, 500.0, 0.1)};
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

TEST(RdaSource, ALostBlockIsZerosOnItsSamplesAndTheNextKeepsItsPlace) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0),
                    dataMessage(2, 16, 4, 32), dataMessage(3, 16, 4, 48)});
  Opened o = openRda(server.port());
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 64);
  ASSERT_EQ(blocks.size(), 4u);
  for (int s = 0; s < 16; ++s) EXPECT_EQ(blocks[1].at(0, s), 0.0f);  // block 1 never came
  EXPECT_EQ(blocks[2].first_sample, 32);
  EXPECT_FLOAT_EQ(blocks[2].at(3, 0), 32 * 10 + 3);
}

TEST(RdaSource, WhatCannotBeReadIsRefusedWithItsReason) {
  auto refusal = [](std::vector<std::vector<std::uint8_t>> messages, double rate = 256.0) {
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
  const std::string sixteen = refusal({message(2, std::vector<std::uint8_t>(12, 0))});
  EXPECT_NE(sixteen.find("16-bit"), std::string::npos) << sixteen;
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

TEST(RdaSource, AStopMessageIsAFaultNotACrash) {
  RdaServer server({startMessage(kNames, 256.0, 1.0), dataMessage(0, 16, 4, 0), message(3, {})});
  Opened o = openRda(server.port());
  const std::vector<bci::Block> blocks = pollSamples(*o.source, 1000);
  EXPECT_EQ(blocks.size(), 1u);  // what came before the stop
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (o.source->fault().empty() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_NE(o.source->fault().find("stopped the stream"), std::string::npos) << o.source->fault();
}

}  // namespace
}  // namespace arbci::session
