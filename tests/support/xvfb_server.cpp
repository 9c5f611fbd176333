#include "support/xvfb_server.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>

namespace arbci::test {

namespace {

// Waits up to `seconds` for the process to exit; true when it did.
bool reaped(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(seconds * 1e3));
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace

XvfbServer::XvfbServer(const std::string& screen) {
  int display_pipe[2];
  if (pipe(display_pipe) != 0) throw std::runtime_error("XvfbServer: pipe failed");
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("XvfbServer: fork failed");
  if (pid_ == 0) {
    setpgid(0, 0);  // not in the test's process group, so a test's kill leaves it to us
    close(display_pipe[0]);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    const std::string fd = std::to_string(display_pipe[1]);
    // -noreset: an X server resets when its last client disconnects, and a connection made
    // while it resets is refused ("Failed to open display"). A test that opens a second window
    // after closing the first, or arbci probing the display before opening its window, would
    // otherwise race the reset.
    execl(XVFB_EXECUTABLE, "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", screen.c_str(),
          "-nolisten", "tcp", "-noreset", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(display_pipe[1]);
  // Xvfb writes the display number and a newline once it accepts connections.
  std::string number;
  pollfd fd{display_pipe[0], POLLIN, 0};
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline && number.find('\n') == std::string::npos) {
    if (poll(&fd, 1, 100) <= 0) continue;
    char buffer[32];
    const ssize_t n = read(display_pipe[0], buffer, sizeof buffer);
    if (n <= 0) break;
    number.append(buffer, static_cast<size_t>(n));
  }
  close(display_pipe[0]);
  const size_t end = number.find('\n');
  if (end == std::string::npos || end == 0) {
    kill(pid_, SIGKILL);
    reaped(pid_, 5.0);
    throw std::runtime_error("Xvfb (" XVFB_EXECUTABLE ") did not report a display within 30 s");
  }
  char display[32];
  std::snprintf(display, sizeof display, ":%d", std::atoi(number.c_str()));
  display_ = display;
}

XvfbServer::~XvfbServer() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  if (!reaped(pid_, 5.0)) {
    kill(pid_, SIGKILL);
    reaped(pid_, 5.0);
  }
}

}  // namespace arbci::test
