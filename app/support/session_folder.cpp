#include "support/session_folder.h"

#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "support/cli_error.h"

namespace arbci::app {

bool holdsOnlyAFailedStart(const std::filesystem::path& folder) {
  std::ifstream in(folder / "summary.json");
  if (!in) return false;
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  if (summary.is_discarded() || !summary.is_object()) return false;
  const std::string reason = summary.value("end_reason", "");
  return reason.rfind("pre-flight failed", 0) == 0 &&
         summary.value("trials", nlohmann::json::array()).empty();
}

void claimFolder(const std::string& out, bool overwrite) {
  std::error_code error;
  if (!std::filesystem::exists(out, error) || std::filesystem::is_empty(out, error)) return;
  if (!std::filesystem::is_directory(out))
    throw CliError("--out " + out + ": exists and is not a folder");
  if (!overwrite && holdsOnlyAFailedStart(out)) {
    std::cerr << "--out " << out << ": holds a session that failed its pre-flight; replacing it\n";
  } else if (!overwrite) {
    throw CliError("--out " + out +
                   ": the folder exists and is not empty (an earlier session?); choose another "
                   "--out, leave it out for a new time-stamped folder, or add --overwrite");
  }
  std::filesystem::remove_all(out, error);
  if (error) throw CliError("--out: cannot empty " + out + ": " + error.message());
}

FolderClaim::~FolderClaim() {
  if (kept_) return;
  std::error_code error;
  if (existed_) {  // claimed empty: empty it again
    for (const auto& entry : std::filesystem::directory_iterator(folder_, error))
      std::filesystem::remove_all(entry.path(), error);
  } else {
    std::filesystem::remove_all(folder_, error);
  }
}

}  // namespace arbci::app
