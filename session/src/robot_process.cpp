#include "arbci/session/robot_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

namespace arbci::session {

std::filesystem::path robotdNextToMe() {
  if (const char* explicit_path = std::getenv("ARBCI_ROBOTD")) return explicit_path;
  std::error_code error;
  const auto me = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path dir = error ? std::filesystem::path(".") : me.parent_path();
  // Next to arbci, or one level up (the benchmarks' and tests' folders of a build tree).
  for (const auto& candidate : {dir / "arbci-robotd", dir.parent_path() / "arbci-robotd"}) {
    if (std::filesystem::exists(candidate)) return candidate;
  }
  return dir / "arbci-robotd";
}

RobotProcess::RobotProcess(const std::filesystem::path& executable,
                           const std::filesystem::path& key_file,
                           const std::filesystem::path& config_file, const std::string& driver,
                           double speed_factor, int watchdog_ms,
                           const std::filesystem::path& folder, bool stepped) {
  if (!std::filesystem::exists(executable))
    throw std::runtime_error(executable.string() +
                             ": the robot backend is not there (build arbci-robotd)");
  const auto port_file = folder / "robotd.port";
  const auto log_file = folder / "robotd.log";
  std::filesystem::remove(port_file);
  const std::string speed = std::to_string(speed_factor);
  const std::string watchdog = std::to_string(watchdog_ms);
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("cannot start arbci-robotd: fork failed");
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // the backend stops with the session, however it ends
    const int log = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) {
      dup2(log, STDERR_FILENO);
      dup2(log, STDOUT_FILENO);
    }
    execl(executable.c_str(), executable.c_str(), "--port", "0", "--port-file", port_file.c_str(),
          "--key-file", key_file.c_str(), "--config", config_file.c_str(), "--driver",
          driver.c_str(), "--speed", speed.c_str(), "--watchdog-ms", watchdog.c_str(),
          stepped ? "--stepped" : nullptr, nullptr);
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    std::ifstream in(port_file);
    if (in >> port_ && port_ > 0) return;
    if (!running()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::ifstream log(log_file);
  std::stringstream text;
  text << log.rdbuf();
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
  throw std::runtime_error("arbci-robotd did not start: " + text.str());
}

bool RobotProcess::running() const {
  if (pid_ <= 0) return false;
  return waitpid(pid_, nullptr, WNOHANG) == 0;
}

RobotProcess::~RobotProcess() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  for (int i = 0; i < 200; ++i) {
    if (waitpid(pid_, nullptr, WNOHANG) != 0) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
}

}  // namespace arbci::session
