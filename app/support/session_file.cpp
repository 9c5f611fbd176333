#include "support/session_file.h"

#include "support/cli_error.h"

namespace arbci::app {

SessionConfig loadSessionOption(const std::string& path) {
  try {
    return SessionConfig::load(path.empty() ? std::nullopt
                                            : std::optional<std::filesystem::path>(path));
  } catch (const SessionConfigError& error) {
    throw CliError(error.what());
  }
}

}  // namespace arbci::app
