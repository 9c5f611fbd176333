// A session's folder is never overwritten by accident: an existing, non-empty --out is refused
// unless --overwrite empties it first, or it holds only a failed start (a session that ended in its
// pre-flight, with no data), which a retry may replace; and until the session has opened, what the
// run wrote into its folder is removed again when it fails.
#pragma once

#include <filesystem>
#include <string>

namespace arbci::app {

// The session folder ended in its pre-flight: its summary says so and it holds no trial.
bool holdsOnlyAFailedStart(const std::filesystem::path& folder);

// Claims `out` for a new session; throws CliError naming --out when it holds a session.
void claimFolder(const std::string& out, bool overwrite);

// Until keep(), the folder is emptied again (or removed, when it did not exist) on destruction: a
// failed start leaves nothing that blocks a retry.
class FolderClaim {
 public:
  explicit FolderClaim(std::filesystem::path folder)
      : folder_(std::move(folder)), existed_(std::filesystem::exists(folder_)) {}
  ~FolderClaim();
  FolderClaim(const FolderClaim&) = delete;
  FolderClaim& operator=(const FolderClaim&) = delete;
  void keep() { kept_ = true; }

 private:
  std::filesystem::path folder_;
  bool existed_;
  bool kept_ = false;
};

}  // namespace arbci::app
