#include "support/name_list.h"

#include <sstream>

namespace arbci::app {

std::vector<std::string> splitNameList(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (!name.empty()) names.push_back(name);
  }
  return names;
}

}  // namespace arbci::app
