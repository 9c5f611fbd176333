// Paths into the shared reference data (../shared/data), which the tests read in place.
#pragma once

#include <string>

namespace arbci::test {

inline std::string sharedData(const std::string& relative) {
  std::string path = ARBCI_SHARED_DATA_DIR;
  return path.append("/").append(relative);
}

}  // namespace arbci::test
