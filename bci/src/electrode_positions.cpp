#include "arbci/bci/electrode_positions.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

namespace arbci::bci {
namespace {

struct Polar {
  double theta_deg;  // from the nose, clockwise seen from above (positive: right)
  double radius;     // 0.5: 90 degrees from the vertex
};

const std::map<std::string, Polar>& table() {
  // The standard 10-20 positions (as EEGLAB's standard cap gives them) and the 10-10 sites
  // on the midline and the 90-degree ring.
  static const std::map<std::string, Polar> positions = {
      {"FPZ", {0, 0.511}},   {"FP1", {-18, 0.511}}, {"FP2", {18, 0.511}},   {"AFZ", {0, 0.383}},
      {"F7", {-54, 0.511}},  {"F3", {-39, 0.333}},  {"FZ", {0, 0.256}},     {"F4", {39, 0.333}},
      {"F8", {54, 0.511}},   {"FCZ", {0, 0.128}},   {"T7", {-90, 0.511}},   {"T3", {-90, 0.511}},
      {"C5", {-90, 0.383}},  {"C3", {-90, 0.256}},  {"C1", {-90, 0.128}},   {"CZ", {0, 0.0}},
      {"C2", {90, 0.128}},   {"C4", {90, 0.256}},   {"C6", {90, 0.383}},    {"T8", {90, 0.511}},
      {"T4", {90, 0.511}},   {"CPZ", {180, 0.128}}, {"P7", {-126, 0.511}},  {"T5", {-126, 0.511}},
      {"P3", {-141, 0.333}}, {"PZ", {180, 0.256}},  {"P4", {141, 0.333}},   {"P8", {126, 0.511}},
      {"T6", {126, 0.511}},  {"POZ", {180, 0.383}}, {"PO7", {-144, 0.511}}, {"PO8", {144, 0.511}},
      {"O1", {-162, 0.511}}, {"OZ", {180, 0.511}},  {"O2", {162, 0.511}},
  };
  return positions;
}

}  // namespace

std::string electrodeKey(const std::string& name) {
  std::string key = name;
  std::transform(key.begin(), key.end(), key.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return key;
}

std::optional<std::pair<double, double>> electrodePosition(const std::string& name) {
  const auto found = table().find(electrodeKey(name));
  if (found == table().end()) return std::nullopt;
  const double theta = found->second.theta_deg * M_PI / 180.0;
  return std::make_pair(found->second.radius * std::sin(theta),
                        found->second.radius * std::cos(theta));
}

}  // namespace arbci::bci
