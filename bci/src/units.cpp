#include "arbci/bci/units.h"

#include <cctype>
#include <string>

namespace arbci::bci {

namespace {

std::string lowered(std::string_view unit) {
  std::string u;
  for (char c : unit) u += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return u;
}

}  // namespace

double microvoltsPer(std::string_view unit) {
  const std::string u = lowered(unit);
  if (u == "v" || u == "volt" || u == "volts") return 1e6;
  if (u == "mv" || u == "millivolt" || u == "millivolts") return 1e3;
  if (u == "nv" || u == "nanovolt" || u == "nanovolts") return 1e-3;
  return 1.0;
}

bool isVoltageUnit(std::string_view unit) {
  const std::string u = lowered(unit);
  return u.empty() || microvoltsPer(u) != 1.0 || u == "uv" || u == "µv" || u == "μv" ||
         u == "microvolt" || u == "microvolts";
}

std::string nonVoltageNote(const std::vector<std::string>& channels,
                           const std::vector<std::string>& units) {
  std::string listed;
  for (size_t k = 0; k < channels.size() && k < units.size(); ++k) {
    if (isVoltageUnit(units[k])) continue;
    listed += (listed.empty() ? "" : ", ") + channels[k] + " (\"" + units[k] + "\")";
  }
  if (listed.empty()) return "";
  return "channel(s) " + listed +
         " are not in a voltage unit: their values are kept as they are, not microvolts";
}

}  // namespace arbci::bci
