#include "support/test_files.h"

#include <fstream>

namespace arbci::test {

std::filesystem::path freshTempPath(const std::string& suite, const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / ("arbci_" + suite + "_" + name);
  std::filesystem::remove_all(path);
  return path;
}

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace arbci::test
