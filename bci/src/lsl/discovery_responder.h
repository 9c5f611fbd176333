// Answers LSL discovery queries on the configuration's discovery addresses (port 16571) for all
// of this process's outlets at once. Many sockets may share that port, but a unicast query (the
// machine scope asks 127.0.0.1) reaches only one of them, the newest bound: one responder per
// process lets every outlet of the process be found, not just the last one opened. A unicast
// query from this machine is passed on to every port of the outlet range on 127.0.0.1, where
// every outlet (liblsl's too) answers shortinfo queries itself, to the asker's address and
// return port: so the outlets of other processes that the kernel did not hand it to, liblsl's
// included, are still found, which liblsl's own responders do not do for one another.
#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/stream_info.h"
#include "lsl/socket.h"

namespace arbci::bci::lsl {

class DiscoveryResponder {
 public:
  // The process's responder for `config`'s discovery port and addresses, started on first use;
  // `warnings` gets why an address could not be served.
  static std::shared_ptr<DiscoveryResponder> shared(const LslConfig& config,
                                                    std::vector<std::string>& warnings);
  DiscoveryResponder(const LslConfig& config, std::vector<std::string>& warnings);
  ~DiscoveryResponder();
  DiscoveryResponder(const DiscoveryResponder&) = delete;
  DiscoveryResponder& operator=(const DiscoveryResponder&) = delete;

  void add(const void* owner, const StreamInfo& info, const std::string& shortinfo);
  void remove(const void* owner);

 private:
  void serve();
  void passOn(size_t socket, const std::string& bytes);
  std::vector<net::Fd> sockets_;
  int base_port_ = 0, port_range_ = 0;
  std::mutex mutex_;
  std::map<const void*, std::pair<StreamInfo, std::string>> outlets_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The reply to a "LSL:shortinfo" request (the lines after the method) for one stream: the port
// to send it to and the text, or nothing when the query does not match or is malformed.
std::optional<std::pair<int, std::string>> shortinfoReply(const std::string& request_lines,
                                                          const StreamInfo& info,
                                                          const std::string& shortinfo);

}  // namespace arbci::bci::lsl
