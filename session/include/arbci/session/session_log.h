// The session's JSON-lines log: one JSON object per line (selections, robot commands and replies,
// phase changes, per-cycle timings), handed to the system as written so a crash of the program
// loses nothing already logged. A line the system cannot take (a full disk, a file over its size
// limit, a lost mount) is cut back off the file, never left half written, and counted; writing
// goes on with the next line, so that the log resumes once there is room, its first line then
// saying how many were lost (event "log_lines_lost"). The session tells the experimenter both.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace arbci::session {

class SessionLog {
 public:
  // Throws std::runtime_error when the file cannot be created.
  explicit SessionLog(const std::filesystem::path& path);
  ~SessionLog();
  SessionLog(const SessionLog&) = delete;
  SessionLog& operator=(const SessionLog&) = delete;

  // Adds "event" and the session time "t" to `fields` and writes the line.
  void write(const std::string& event, double t, nlohmann::json fields = nlohmann::json::object());

  // Lines lost since the log was opened; whether the last line was.
  int lost() const { return lost_total_; }
  bool failing() const { return failing_; }
  // What changed since the last call, for the experimenter, once: "" when nothing did; else that
  // writing failed (and why) or that it resumed (and how many lines were lost).
  std::string news();

 private:
  bool writeAll(const std::string& line);  // whole or, cut back off, not at all
  std::filesystem::path path_;
  int fd_ = -1;
  long long good_size_ = 0;  // the file's length after its last whole line
  bool failing_ = false;
  int lost_now_ = 0, lost_total_ = 0;  // since failing; in all
  std::string news_;
};

}  // namespace arbci::session
