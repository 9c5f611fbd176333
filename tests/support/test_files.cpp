#include "support/test_files.h"

#include <unistd.h>

#include <fstream>

namespace arbci::test {

std::filesystem::path freshTempPath(const std::string& suite, const std::string& name) {
  // The process id keeps apart the tests that ctest runs side by side (each test case its own
  // process): two cases naming the same file raced, one reading the other's.
  const auto path = std::filesystem::temp_directory_path() /
                    ("arbci_" + suite + "_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(path);
  return path;
}

std::filesystem::path scratchPath(const std::string& folder, const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / folder;
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace arbci::test
