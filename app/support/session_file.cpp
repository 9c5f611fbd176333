#include "support/session_file.h"

#include "support/cli_error.h"

namespace arbci::app {

session::SessionConfig loadSessionOption(const std::string& path) {
  try {
    return session::SessionConfig::load(path.empty() ? std::nullopt
                                                     : std::optional<std::filesystem::path>(path));
  } catch (const session::SessionConfigError& error) {
    throw CliError(error.what());
  }
}

}  // namespace arbci::app
