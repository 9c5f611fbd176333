// arbci-robotd as a child process of the session: started with a fresh key on a free port of
// 127.0.0.1, its log in the session folder, stopped with the session.
#pragma once

#include <sys/types.h>

#include <filesystem>

namespace arbci::session {

class RobotProcess {
 public:
  // `stepped`: the arm moves on the session's clock (arbci-robotd --stepped).
  // Starts `executable` and waits (at most 10 s) until it listens. Throws std::runtime_error
  // with the reason (and the end of its log) when it does not come up.
  RobotProcess(const std::filesystem::path& executable, const std::filesystem::path& key_file,
               const std::filesystem::path& config_file, const std::string& driver,
               double speed_factor, int watchdog_ms, const std::filesystem::path& folder,
               bool stepped = false);
  ~RobotProcess();  // SIGTERM, then SIGKILL after 2 s
  RobotProcess(const RobotProcess&) = delete;
  RobotProcess& operator=(const RobotProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  bool running() const;

 private:
  pid_t pid_ = -1;
  int port_ = 0;
};

// The arbci-robotd to start: $ARBCI_ROBOTD, else the one next to the running executable (or one
// folder up, as in a build tree).
std::filesystem::path robotdNextToMe();

}  // namespace arbci::session
