// A program started beside the test (a second process: an LSL outlet, a stand-in amplifier),
// killed with its process group when the test ends. Its stdout is read line by line with a
// bounded wait.
#pragma once

#include <sys/types.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace arbci::test {

class BackgroundProcess {
 public:
  // `environment`: variables set (or replaced) for the child.
  BackgroundProcess(const std::string& program, const std::vector<std::string>& arguments,
                    const std::map<std::string, std::string>& environment = {});
  ~BackgroundProcess();
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;

  // The next line of its stdout, or nothing after `timeout_s` or when it closed stdout.
  std::optional<std::string> readLine(double timeout_s);
  // The first line starting with `prefix` within `timeout_s` (lines before it are skipped).
  std::optional<std::string> waitForLine(const std::string& prefix, double timeout_s);
  // Sends `signal` to the process alone (SIGTERM: end as Ctrl+C would).
  void signal(int signal_number);
  // SIGKILL to the group, then reaped; idempotent.
  void kill();
  // Waits up to `timeout_s` for it to exit by itself; its exit status, or nothing.
  std::optional<int> wait(double timeout_s);
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  std::string buffer_;
  bool reaped_ = false;
};

}  // namespace arbci::test
