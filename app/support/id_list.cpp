#include "support/id_list.h"

#include <sstream>

#include "support/cli_error.h"

namespace arbci::app {
namespace {

int parseId(const std::string& text, int max_id) {
  size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty()) throw CliError("'" + text + "' is not a marker id");
  if (value < 0 || value > max_id) {
    throw CliError("marker id " + text + " is outside 0.." + std::to_string(max_id));
  }
  return value;
}

}  // namespace

std::vector<int> parseIdList(const std::string& text, int max_id) {
  std::vector<int> ids;
  std::stringstream parts(text);
  std::string part;
  while (std::getline(parts, part, ',')) {
    const size_t dash = part.find('-', 1);
    if (dash == std::string::npos) {
      ids.push_back(parseId(part, max_id));
      continue;
    }
    const int first = parseId(part.substr(0, dash), max_id),
              last = parseId(part.substr(dash + 1), max_id);
    if (last < first) throw CliError("id range " + part + " runs backwards");
    for (int id = first; id <= last; ++id) ids.push_back(id);
  }
  if (ids.empty()) throw CliError("no marker ids given");
  return ids;
}

}  // namespace arbci::app
