#include "support/output_path.h"

#include <cerrno>
#include <cstring>
#include <fstream>

#include "support/cli_error.h"

namespace arbci::app {

void ensureWritable(const std::filesystem::path& path, bool create_parents) {
  if (path.empty()) throw CliError("no output path given");
  if (std::filesystem::is_directory(path)) {
    throw CliError("cannot write " + path.string() + ": it is a directory");
  }
  const std::filesystem::path parent = path.parent_path();
  if (create_parents && !parent.empty()) {
    std::error_code error;
    std::filesystem::create_directories(parent, error);
    if (error) throw CliError("cannot create folder " + parent.string() + ": " + error.message());
  }
  const bool existed = std::filesystem::exists(path);
  std::ofstream probe(path, std::ios::app);
  if (!probe) {
    throw CliError("cannot write " + path.string() + ": " + std::strerror(errno));
  }
  probe.close();
  if (!existed) std::filesystem::remove(path);
}

void ensureWritableFolder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw CliError("cannot create folder " + folder.string() + ": " + error.message());
  ensureWritable(folder / ".arbci-write-check");
}

}  // namespace arbci::app
