#include "arbci/bci/lsl/resolver.h"

#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <map>
#include <sstream>

#include "arbci/bci/lsl/outlet.h"
#include "lsl/socket.h"

namespace arbci::bci::lsl {
namespace {

constexpr double kWaveIntervalS = 0.5;
constexpr double kGraceS = 0.2;  // after the minimum has answered, for the others

std::vector<sockaddr_in> peerAddresses(const std::string& host) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  std::vector<sockaddr_in> out;
  if (::getaddrinfo(host.c_str(), nullptr, &hints, &found) != 0) return out;
  for (addrinfo* a = found; a; a = a->ai_next)
    out.push_back(*reinterpret_cast<sockaddr_in*>(a->ai_addr));
  ::freeaddrinfo(found);
  return out;
}

}  // namespace

std::vector<StreamInfo> resolveStreams(const LslConfig& config, const std::string& query,
                                       double timeout_s, int minimum) {
  StreamInfo probe;
  probe.name = "probe";
  probe.matches(query);  // throws for a query that is not XPath

  const bool machine = config.machineOnly();
  net::Fd receiver = net::udpSocket();
  net::bindInRange(receiver, machine ? "127.0.0.1" : "0.0.0.0", config.base_port, config.port_range,
                   true);
  sockaddr_in bound{};
  socklen_t length = sizeof bound;
  ::getsockname(receiver.get(), reinterpret_cast<sockaddr*>(&bound), &length);
  const int one = 1, ttl = config.multicastTtl();
  ::setsockopt(receiver.get(), SOL_SOCKET, SO_BROADCAST, &one, sizeof one);
  ::setsockopt(receiver.get(), IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);

  const std::string query_id = std::to_string(std::hash<std::string>()(query));
  const std::string message = "LSL:shortinfo\r\n" + query + "\r\n" +
                              std::to_string(ntohs(bound.sin_port)) + " " + query_id + "\r\n";

  // Where to ask: the discovery addresses on the discovery port; every port of the range on the
  // known peers and, for the machine scope, on loopback (outlets that could not share the
  // discovery port still answer on their own service port).
  std::vector<sockaddr_in> targets;
  for (const auto& a : config.queryAddresses())
    targets.push_back(net::endpoint(a, config.multicast_port));
  std::vector<sockaddr_in> hosts;
  for (const auto& peer : config.known_peers)
    for (const auto& a : peerAddresses(peer)) hosts.push_back(a);
  if (machine) hosts.push_back(net::endpoint("127.0.0.1", 0));
  for (sockaddr_in host : hosts)
    for (int p = config.base_port; p < config.base_port + config.port_range; ++p) {
      host.sin_port = htons(static_cast<std::uint16_t>(p));
      targets.push_back(host);
    }

  std::map<std::string, StreamInfo> found;
  const double start = localClock(), deadline = start + timeout_s;
  double next_wave = start, enough_at = -1;
  while (localClock() < deadline) {
    if (localClock() >= next_wave) {
      for (const auto& t : targets) net::sendDatagram(receiver, message, t);
      next_wave += kWaveIntervalS;
    }
    if (enough_at > 0 && localClock() >= enough_at) break;
    const double wait = std::max(0.0, std::min(next_wave, deadline) - localClock());
    auto reply = net::receiveDatagram(receiver, std::min(wait, 0.05));
    if (!reply) continue;
    const auto newline = reply->bytes.find('\n');
    if (newline == std::string::npos) continue;
    std::string id = reply->bytes.substr(0, newline);
    if (!id.empty() && id.back() == '\r') id.pop_back();
    if (id != query_id) continue;
    try {
      StreamInfo info = StreamInfo::fromXml(reply->bytes.substr(newline + 1));
      if (info.v4address.empty()) info.v4address = net::addressText(reply->from);
      found.emplace(info.uid, std::move(info));
    } catch (const LslError&) {
      continue;  // a malformed reply is not a stream
    }
    if (minimum > 0 && static_cast<int>(found.size()) >= minimum && enough_at < 0)
      enough_at = localClock() + kGraceS;
  }
  std::vector<StreamInfo> out;
  for (auto& [uid, info] : found) out.push_back(std::move(info));
  return out;
}

StreamInfo fetchFullInfo(const StreamInfo& stream, double timeout_s) {
  net::TcpStream connection{
      net::tcpConnect(net::endpoint(stream.v4address, stream.v4data_port), timeout_s)};
  connection.writeAll("LSL:fullinfo\r\n", timeout_s);
  StreamInfo full = StreamInfo::fromXml(connection.readAll(timeout_s));
  full.v4address = stream.v4address;
  return full;
}

}  // namespace arbci::bci::lsl
