// The session's JSON-lines log: one JSON object per line (selections, robot commands and replies,
// phase changes, per-cycle timings), flushed as written so a crash loses nothing already logged.
#pragma once

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace arbci::session {

class SessionLog {
 public:
  explicit SessionLog(const std::filesystem::path& path);
  // Adds "event" and the session time "t" to `fields` and writes the line.
  void write(const std::string& event, double t, nlohmann::json fields = nlohmann::json::object());

 private:
  std::ofstream out_;
};

}  // namespace arbci::session
