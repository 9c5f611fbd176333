#include "lsl/discovery_responder.h"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <sstream>

#include "arbci/core/text.h"

namespace arbci::bci::lsl {
namespace {}  // namespace

std::optional<std::pair<int, std::string>> shortinfoReply(const std::string& request_lines,
                                                          const StreamInfo& info,
                                                          const std::string& shortinfo) {
  std::istringstream request(request_lines);
  std::string query, ids;
  std::getline(request, query);
  std::getline(request, ids);
  std::istringstream fields(ids);
  int port = 0;
  std::string id;
  if (!(fields >> port >> id) || port <= 0 || port > 65535) return std::nullopt;
  try {
    if (!info.matches(core::trimmed(query))) return std::nullopt;
  } catch (const LslError&) {
    return std::nullopt;  // an invalid query matches nothing
  }
  return std::pair{port, id + "\r\n" + shortinfo};
}

std::shared_ptr<DiscoveryResponder> DiscoveryResponder::shared(const LslConfig& config,
                                                               std::vector<std::string>& warnings) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<DiscoveryResponder>> responders;
  std::string key = std::to_string(config.multicast_port);
  for (const auto& a : config.queryAddresses()) key += " " + a;
  std::lock_guard lock(mutex);
  if (auto existing = responders[key].lock()) return existing;
  auto made = std::make_shared<DiscoveryResponder>(config, warnings);
  responders[key] = made;
  return made;
}

DiscoveryResponder::DiscoveryResponder(const LslConfig& config, std::vector<std::string>& warnings)
    : base_port_(config.base_port), port_range_(config.port_range) {
  // Every address on the discovery port bound on any address, with the port shared, as liblsl's
  // responders bind it (joining the group where the address is multicast). A loopback address
  // bound as itself would be more specific than liblsl's binding: the kernel would hand every
  // unicast query to 127.0.0.1 to ARBCI alone, and liblsl's consumers would stop finding liblsl's
  // outlets in the machine scope.
  for (const auto& a : config.queryAddresses()) {
    try {
      net::Fd fd = net::udpSocket();
      const sockaddr_in group = net::endpoint(a, config.multicast_port);
      const bool multicast = IN_MULTICAST(ntohl(group.sin_addr.s_addr));
      net::bindExact(fd, "0.0.0.0", config.multicast_port, true);
      if (multicast) {
        ip_mreq membership{};
        membership.imr_multiaddr = group.sin_addr;
        membership.imr_interface.s_addr = htonl(INADDR_ANY);
        if (::setsockopt(fd.get(), IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) !=
            0)
          throw LslError("cannot join the multicast group " + a);
      }
      sockets_.push_back(std::move(fd));
    } catch (const LslError& e) {
      warnings.push_back("discovery on " + a + ":" + std::to_string(config.multicast_port) + ": " +
                         e.what());
    }
  }
  thread_ = std::thread([this] { serve(); });
}

DiscoveryResponder::~DiscoveryResponder() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void DiscoveryResponder::add(const void* owner, const StreamInfo& info,
                             const std::string& shortinfo) {
  std::lock_guard lock(mutex_);
  outlets_[owner] = {info, shortinfo};
}

void DiscoveryResponder::remove(const void* owner) {
  std::lock_guard lock(mutex_);
  outlets_.erase(owner);
}

void DiscoveryResponder::serve() {
  std::vector<pollfd> watched;
  for (const auto& s : sockets_) watched.push_back({s.get(), POLLIN, 0});
  while (!stop_) {
    for (auto& w : watched) w.revents = 0;
    if (watched.empty() || ::poll(watched.data(), watched.size(), 100) <= 0) {
      if (watched.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
      continue;
    }
    for (size_t i = 0; i < watched.size(); ++i) {
      if (!(watched[i].revents & POLLIN)) continue;
      auto datagram = net::receiveDatagram(sockets_[i], 0.0);
      if (!datagram) continue;
      const auto newline = datagram->bytes.find('\n');
      if (newline == std::string::npos ||
          core::trimmed(datagram->bytes.substr(0, newline)) != "LSL:shortinfo")
        continue;
      const std::string rest = datagram->bytes.substr(newline + 1);
      if (ntohl(datagram->from.sin_addr.s_addr) == INADDR_LOOPBACK) passOn(i, datagram->bytes);
      std::lock_guard lock(mutex_);
      for (const auto& [owner, outlet] : outlets_) {
        if (auto reply = shortinfoReply(rest, outlet.first, outlet.second)) {
          sockaddr_in to = datagram->from;
          to.sin_port = htons(static_cast<std::uint16_t>(reply->first));
          net::sendDatagram(sockets_[i], reply->second, to);
        }
      }
    }
  }
}

// The query as it came, to each port of the range on 127.0.0.1 but this process's outlets' (it
// answers for them itself). Sent from 127.0.0.1, so each outlet's reply goes to the asker.
void DiscoveryResponder::passOn(size_t socket, const std::string& bytes) {
  std::vector<int> own;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [owner, outlet] : outlets_) own.push_back(outlet.first.v4service_port);
  }
  for (int port = base_port_; port < base_port_ + port_range_; ++port) {
    if (std::find(own.begin(), own.end(), port) != own.end()) continue;
    net::sendDatagram(sockets_[socket], bytes, net::endpoint("127.0.0.1", port));
  }
}

}  // namespace arbci::bci::lsl
