// `arbci robot keygen`, `arbci-robotd` and `arbci robot ...` from the shell: a private key, a
// grasp and drop that exit 0, rejections and a missing backend that exit 1 with the reason.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "support/run_process.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::string kRobotd = ARBCI_ROBOTD_EXECUTABLE;

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_robot_cli_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

// arbci-robotd as a child process, terminated at the end of the test.
class Robotd {
 public:
  Robotd(const std::vector<std::string>& arguments) {
    pid_ = fork();
    if (pid_ == 0) {
      std::vector<char*> argv{const_cast<char*>(kRobotd.c_str())};
      for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(kRobotd.c_str(), argv.data());
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  ~Robotd() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }

 private:
  pid_t pid_;
};

TEST(RobotCommand, KeygenWritesAPrivateKey) {
  const auto key = scratch("cli.key");
  const ProcessResult r = runProcess(kArbci, {"robot", "keygen", "--out", key.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  struct stat info {};
  ASSERT_EQ(stat(key.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  std::ifstream in(key);
  std::string hex;
  in >> hex;
  EXPECT_EQ(hex.size(), 64u);
}

TEST(RobotCommand, GraspDropAndRejectionsThroughTheBackend) {
  const auto key = scratch("session.key"), config = scratch("robot.json");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  std::ofstream(config)
      << R"({"speed_factor": 20, "objects": [{"id": 4, "position": [0.1, 0.6, 0.06]}]})";
  const std::string port = "47913";
  Robotd robotd({"--port", port, "--key-file", key.string(), "--config", config.string()});
  const std::vector<std::string> base{"robot", "--port", port, "--key-file", key.string()};
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return runProcess(kArbci, args, 60.0);
  };
  ProcessResult r = run({"grasp", "0.1", "0.6", "0.06"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("holding object 4"), std::string::npos) << r.out;
  r = run({"drop", "-0.1", "0.7", "0"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run({"status"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("object 4: (-0.100, 0.700, 0.060)"), std::string::npos) << r.out;
  r = run({"grasp", "3", "0", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("outside the workspace"), std::string::npos) << r.err;
  r = run({"drop", "0.1", "0.6", "0"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("holding nothing"), std::string::npos) << r.err;
}

TEST(RobotCommand, NoBackendOrWrongKeyGivesAReason) {
  const auto key = scratch("lonely.key");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  const auto start = std::chrono::steady_clock::now();
  const ProcessResult r =
      runProcess(kArbci, {"robot", "--port", "47999", "--key-file", key.string(), "home"}, 30.0);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no answer from the backend"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  const ProcessResult missing =
      runProcess(kArbci, {"robot", "--key-file", scratch("none.key").string(), "status"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("no key file"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace arbci::test
