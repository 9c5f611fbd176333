#include "arbci/bci/lsl/config.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "arbci/core/text.h"

namespace arbci::bci::lsl {
namespace {

// liblsl's set syntax: {a, b, c}.
std::vector<std::string> parseSet(const std::string& value, const std::string& where) {
  const std::string v = core::trimmed(value);
  if (v.size() < 2 || v.front() != '{' || v.back() != '}')
    throw LslError(where + ": \"" + v + "\" is not a set (write it as {a, b, ...})");
  std::vector<std::string> out;
  std::stringstream items(v.substr(1, v.size() - 2));
  std::string item;
  while (std::getline(items, item, ','))
    if (!core::trimmed(item).empty()) out.push_back(core::trimmed(item));
  return out;
}

bool isIpv4(const std::string& address) {
  in_addr parsed{};
  return inet_pton(AF_INET, address.c_str(), &parsed) == 1;
}

int parseInt(const std::string& value, const std::string& where, int low, int high) {
  try {
    size_t used = 0;
    const int v = std::stoi(value, &used);
    if (used == value.size() && v >= low && v <= high) return v;
  } catch (const std::exception&) {
  }
  throw LslError(where + ": \"" + value + "\" is not a whole number from " + std::to_string(low) +
                 " to " + std::to_string(high));
}

double parseDouble(const std::string& value, const std::string& where) {
  try {
    size_t used = 0;
    const double v = std::stod(value, &used);
    if (used == value.size() && v > 0) return v;
  } catch (const std::exception&) {
  }
  throw LslError(where + ": \"" + value + "\" is not a positive number");
}

}  // namespace

LslConfig LslConfig::load() {
  if (const char* named = std::getenv("LSLAPICFG")) {
    if (!std::ifstream(named).good())
      throw LslError(std::string("LSLAPICFG names \"") + named + "\", which cannot be read");
    return fromFile(named);
  }
  std::vector<std::string> candidates{"lsl_api.cfg"};
  if (const char* home = std::getenv("HOME"))
    candidates.push_back(std::string(home) + "/lsl_api/lsl_api.cfg");
  candidates.push_back("/etc/lsl_api/lsl_api.cfg");
  for (const auto& candidate : candidates)
    if (std::ifstream(candidate).good()) return fromFile(candidate);
  return LslConfig{};
}

LslConfig LslConfig::fromFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw LslError(path + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

LslConfig LslConfig::parse(const std::string& text, const std::string& origin) {
  std::map<std::string, std::string> values;  // "section.Key" -> value
  std::stringstream lines(text);
  std::string line, section;
  for (int number = 1; std::getline(lines, line); ++number) {
    const std::string where = origin + ":" + std::to_string(number);
    const std::string t = core::trimmed(line);
    if (t.empty() || t[0] == ';' || t[0] == '#') continue;
    if (t[0] == '[') {
      const auto close = t.find(']');
      if (close == std::string::npos) throw LslError(where + ": no closing ] for the section");
      section = core::trimmed(t.substr(1, close - 1)) + ".";
      continue;
    }
    const auto eq = t.find('=');
    if (eq == std::string::npos) throw LslError(where + ": expected key = value");
    const std::string key = core::trimmed(t.substr(0, eq)), value = core::trimmed(t.substr(eq + 1));
    if (key.empty() || value.empty()) throw LslError(where + ": empty key or value");
    values[section + key] = value;
  }

  LslConfig c;
  c.source = origin;
  const auto take = [&](const std::string& key) -> const std::string* {
    const auto found = values.find(key);
    return found == values.end() ? nullptr : &found->second;
  };
  const std::string at = origin + ": ";
  if (auto v = take("ports.MulticastPort"))
    c.multicast_port = static_cast<std::uint16_t>(parseInt(*v, at + "MulticastPort", 1, 65535));
  if (auto v = take("ports.BasePort"))
    c.base_port = static_cast<std::uint16_t>(parseInt(*v, at + "BasePort", 1, 65535));
  if (auto v = take("ports.PortRange")) c.port_range = parseInt(*v, at + "PortRange", 1, 65535);
  if (auto v = take("ports.AllowRandomPorts")) c.allow_random_ports = (*v == "1" || *v == "true");
  if (auto v = take("ports.IPv6")) {
    static const std::vector<std::string> known{"allow",    "allowed", "disable",
                                                "disabled", "force",   "forced"};
    if (std::find(known.begin(), known.end(), *v) == known.end())
      throw LslError(at + "IPv6 = \"" + *v + "\": use allow, disable or force");
    c.ipv6 = *v;
    if (*v == "force" || *v == "forced")
      throw LslError(at + "IPv6 = " + *v + ": ARBCI speaks LSL over IPv4 only");
  }
  if (auto v = take("multicast.ResolveScope")) {
    if (*v != "machine" && *v != "link" && *v != "site" && *v != "organization" && *v != "global")
      throw LslError(at + "ResolveScope = \"" + *v +
                     "\": use machine, link, site, organization or global");
    c.resolve_scope = *v;
  }
  if (auto v = take("multicast.MachineAddresses"))
    c.machine_addresses = parseSet(*v, at + "MachineAddresses");
  if (auto v = take("multicast.LinkAddresses"))
    c.link_addresses = parseSet(*v, at + "LinkAddresses");
  if (auto v = take("multicast.SiteAddresses"))
    c.site_addresses = parseSet(*v, at + "SiteAddresses");
  if (auto v = take("multicast.AddressesOverride"))
    c.addresses_override = parseSet(*v, at + "AddressesOverride");
  if (auto v = take("multicast.TTLOverride"))
    c.multicast_ttl_override = parseInt(*v, at + "TTLOverride", -1, 255);
  if (auto v = take("lab.KnownPeers")) c.known_peers = parseSet(*v, at + "KnownPeers");
  if (auto v = take("lab.SessionID")) c.session_id = *v;
  if (auto v = take("tuning.TimeProbeCount"))
    c.time_probe_count = parseInt(*v, at + "TimeProbeCount", 1, 1000);
  if (auto v = take("tuning.TimeProbeInterval"))
    c.time_probe_interval_s = parseDouble(*v, at + "TimeProbeInterval");
  if (auto v = take("tuning.TimeUpdateInterval"))
    c.time_update_interval_s = parseDouble(*v, at + "TimeUpdateInterval");
  return c;
}

std::vector<std::string> LslConfig::queryAddresses() const {
  std::vector<std::string> all;
  if (!addresses_override.empty()) {
    all = addresses_override;
  } else {
    all = machine_addresses;
    if (resolve_scope != "machine")
      all.insert(all.end(), link_addresses.begin(), link_addresses.end());
    if (resolve_scope != "machine" && resolve_scope != "link")
      all.insert(all.end(), site_addresses.begin(), site_addresses.end());
  }
  std::vector<std::string> ipv4;
  for (const auto& a : all)
    if (isIpv4(a)) ipv4.push_back(a);
  return ipv4;
}

int LslConfig::multicastTtl() const {
  if (multicast_ttl_override >= 0) return multicast_ttl_override;
  if (resolve_scope == "machine") return 0;
  if (resolve_scope == "link") return 1;
  if (resolve_scope == "site") return 24;
  return resolve_scope == "organization" ? 32 : 255;
}

bool LslConfig::machineOnly() const {
  if (!known_peers.empty()) return false;
  for (const auto& a : queryAddresses())
    if (a.rfind("127.", 0) != 0) return false;
  return true;
}

std::string LslConfig::describe() const {
  std::string addresses, peers;
  for (const auto& a : queryAddresses()) addresses += (addresses.empty() ? "" : ", ") + a;
  for (const auto& p : known_peers) peers += (peers.empty() ? "" : ", ") + p;
  std::string text = "scope ";
  text += resolve_scope;
  text += " (";
  text += addresses.empty() ? std::string("no IPv4 address") : addresses;
  text += " port ";
  text += std::to_string(multicast_port);
  text += "), known peers {";
  text += peers;
  text += "}, ports ";
  text += std::to_string(base_port);
  text += "-";
  text += std::to_string(base_port + port_range - 1);
  text += ", session ";
  text += session_id;
  text += ", from ";
  text += source;
  return text;
}

}  // namespace arbci::bci::lsl
