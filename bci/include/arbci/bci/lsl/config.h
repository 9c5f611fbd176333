// The Lab Streaming Layer settings ARBCI shares with liblsl: the same configuration file
// (`lsl_api.cfg`, found where liblsl looks for it), the same keys and defaults, so a lab's
// existing set-up (scope, known peers, ports) applies to ARBCI unchanged.
//
// Discovery scope, as liblsl names it: `machine` asks only this host's loopback addresses, `link`
// adds the local link's broadcast and multicast groups, `site` the site-wide multicast group.
// Known peers are asked directly (unicast) whatever the scope. ARBCI speaks IPv4 only: IPv6
// addresses in the file are ignored (and said so by describe()).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace arbci::bci::lsl {

class LslError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LslConfig {
  std::string source = "built-in defaults";  // the file it was read from
  std::uint16_t multicast_port = 16571;
  std::uint16_t base_port = 16572;
  int port_range = 32;
  bool allow_random_ports = true;
  std::string ipv6 = "allow";  // read, reported; ARBCI uses IPv4 only
  std::string resolve_scope = "site";
  std::vector<std::string> machine_addresses{"127.0.0.1"};
  std::vector<std::string> link_addresses{"255.255.255.255", "224.0.0.1", "224.0.0.183"};
  std::vector<std::string> site_addresses{"239.255.172.215"};
  std::vector<std::string> addresses_override;
  std::vector<std::string> known_peers;
  std::string session_id = "default";
  int multicast_ttl_override = -1;
  // Time correction (liblsl's tuning keys): probes per estimate, their spacing, the refresh.
  int time_probe_count = 8;
  double time_probe_interval_s = 0.064;
  double time_update_interval_s = 2.0;

  // The file liblsl would read: $LSLAPICFG, ./lsl_api.cfg, ~/lsl_api/lsl_api.cfg,
  // /etc/lsl_api/lsl_api.cfg; built-in defaults when there is none. Throws LslError for a file
  // that is named by LSLAPICFG but unreadable, or that does not parse.
  static LslConfig load();
  static LslConfig fromFile(const std::string& path);
  // Parses the INI text (`origin` names it in errors).
  static LslConfig parse(const std::string& text, const std::string& origin);

  // The IPv4 addresses discovery queries go to on `multicast_port`, for the scope (loopback,
  // broadcast and multicast groups), IPv6 ones left out.
  std::vector<std::string> queryAddresses() const;
  int multicastTtl() const;
  // True when only this machine is asked and served (scope machine and no known peers): outlets
  // then listen on 127.0.0.1 only.
  bool machineOnly() const;
  // One line for logs: scope, addresses, peers, file.
  std::string describe() const;
};

}  // namespace arbci::bci::lsl
