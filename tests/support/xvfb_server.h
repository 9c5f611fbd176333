// An X server (Xvfb) for the window tests, started and stopped by the test itself.
#pragma once

#include <sys/types.h>

#include <string>

namespace arbci::test {

// Starts Xvfb on a display it picks itself (-displayfd: no race for a free number between tests)
// and stops it when destroyed. Used instead of xvfb-run, whose clean-up can fail and replace the
// program's exit status with its own (5).
class XvfbServer {
 public:
  explicit XvfbServer(const std::string& screen = "1280x720x24");
  ~XvfbServer();
  XvfbServer(const XvfbServer&) = delete;
  XvfbServer& operator=(const XvfbServer&) = delete;

  // ":N", for DISPLAY.
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

}  // namespace arbci::test
