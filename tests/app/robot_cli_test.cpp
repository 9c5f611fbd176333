// `arbci robot keygen`, `arbci-robotd` and `arbci robot ...` from the shell: a private key, a
// grasp and drop that exit 0, rejections and a missing backend that exit 1 with the reason, a
// STOP that holds until `reset`, and at 50 % loss each way every command that ran reported as
// run; a motion whose answer was lost is told apart from one that did not run.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include "arbci/robot/key_file.h"
#include "support/robot_test_support.h"
#include "support/run_process.h"
#include "support/test_files.h"
#include "support/udp_relay.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;
const std::string kRobotd = ARBCI_ROBOTD_EXECUTABLE;

// Per process: keygen never replaces a key, so a folder kept from an earlier run would refuse.
const std::string kScratch = "arbci_robot_cli_test_" + std::to_string(::getpid());

// arbci-robotd as a child process on a free port (port 0; it writes the port it took to a file),
// terminated at the end of the test.
class Robotd {
 public:
  Robotd(const std::string& name, std::vector<std::string> arguments) {
    const auto port_file = scratchPath(kScratch, name + ".port");
    std::filesystem::remove(port_file);
    arguments.insert(arguments.end(), {"--port", "0", "--port-file", port_file.string()});
    pid_ = fork();
    if (pid_ == 0) {
      std::vector<char*> argv{const_cast<char*>(kRobotd.c_str())};
      for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(kRobotd.c_str(), argv.data());
      _exit(127);
    }
    // Listening once the file holds a port (written after the socket is bound).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (port_.empty() && std::chrono::steady_clock::now() < deadline) {
      std::ifstream in(port_file);
      std::string line;
      if (std::getline(in, line) && !line.empty())
        port_ = line;
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (port_.empty()) ADD_FAILURE() << "arbci-robotd wrote no port file";
  }
  ~Robotd() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  const std::string& port() const { return port_; }

 private:
  pid_t pid_;
  std::string port_;
};

TEST(RobotCommand, KeygenWritesAPrivateKey) {
  const auto key = scratchPath(kScratch, "cli.key");
  const ProcessResult r = runProcess(kArbci, {"robot", "keygen", "--out", key.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  struct stat info {};
  ASSERT_EQ(stat(key.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
  std::ifstream in(key);
  std::string hex;
  in >> hex;
  EXPECT_EQ(hex.size(), 64u);
  // A second keygen to the same file is refused and leaves the key; --force replaces it.
  const ProcessResult again = runProcess(kArbci, {"robot", "keygen", "--out", key.string()});
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("never replaced silently"), std::string::npos) << again.err;
  std::ifstream kept(key);
  std::string still;
  kept >> still;
  EXPECT_EQ(still, hex);
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--force", "--out", key.string()}).exit_code, 0);
  std::ifstream replaced(key);
  std::string fresh;
  replaced >> fresh;
  EXPECT_NE(fresh, hex);
  // A FIFO is refused at once (it used to block keygen) and is still a FIFO afterwards.
  const auto fifo = scratchPath(kScratch, "cli.fifo");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const ProcessResult to_fifo =
      runProcess(kArbci, {"robot", "keygen", "--force", "--out", fifo.string()}, 60.0);
  EXPECT_EQ(to_fifo.exit_code, 1);
  EXPECT_NE(to_fifo.err.find("not a regular file"), std::string::npos) << to_fifo.err;
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
}

// A wrong key file is named as such by the command line, not taken for a missing backend: the
// backend answers a HELLO it cannot verify with KEY MISMATCH. (A session's robot stage puts it on
// the record and its pre-flight names it: tests/session/stages.)
TEST(RobotCommand, AWrongKeyIsNamedAsSuchNotAsAMissingBackend) {
  const auto key = scratchPath(kScratch, "right.key"), wrong = scratchPath(kScratch, "wrong.key");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--force", "--out", key.string()}).exit_code, 0);
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--force", "--out", wrong.string()}).exit_code,
            0);
  Robotd robotd("wrong_key", {"--key-file", key.string()});
  const std::string port = robotd.port();
  const ProcessResult cli =
      runProcess(kArbci, {"robot", "--port", port, "--key-file", wrong.string(), "status"}, 60.0);
  EXPECT_EQ(cli.exit_code, 1) << cli.err;
  EXPECT_NE(cli.err.find("answered that our key is not its key"), std::string::npos) << cli.err;
}

TEST(RobotCommand, GraspDropAndRejectionsThroughTheBackend) {
  const auto key = scratchPath(kScratch, "session.key"),
             config = scratchPath(kScratch, "robot.json");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  std::ofstream(config)
      << R"({"speed_factor": 20, "objects": [{"id": 4, "position": [0.1, 0.6, 0.06]}]})";
  Robotd robotd("session", {"--key-file", key.string(), "--config", config.string()});
  const std::string port = robotd.port();
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
  const auto key = scratchPath(kScratch, "lonely.key");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  // A port that is taken and never answers: a socket of the test's own, bound and never read.
  const robot::UdpSocket silent(0, "127.0.0.1");
  const auto start = std::chrono::steady_clock::now();
  const ProcessResult r = runProcess(kArbci,
                                     {"robot", "--port", std::to_string(silent.port()),
                                      "--key-file", key.string(), "--retry-budget", "2", "home"},
                                     60.0);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("HOME not run: no answer from the backend"), std::string::npos) << r.err;
  // The whole retry budget was spent (at least 2 s went by; load only adds to it), and the command
  // ended by itself, saying so (a client that kept retrying would have been killed at 60 s,
  // without this message).
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(took, 2.0);
  EXPECT_NE(r.err.find("in 2 s"), std::string::npos) << r.err;
  const ProcessResult missing = runProcess(
      kArbci, {"robot", "--key-file", scratchPath(kScratch, "none.key").string(), "status"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("no key file"), std::string::npos) << missing.err;
}

TEST(RobotCommand, AStopHoldsUntilReset) {
  const auto key = scratchPath(kScratch, "stop.key");
  ASSERT_EQ(runProcess(kArbci, {"robot", "keygen", "--out", key.string()}).exit_code, 0);
  Robotd robotd("stop", {"--key-file", key.string(), "--speed", "20"});
  const std::string port = robotd.port();
  const std::vector<std::string> base{"robot", "--port", port, "--key-file", key.string()};
  auto run = [&](const std::string& command) {
    std::vector<std::string> args = base;
    args.push_back(command);
    return runProcess(kArbci, args, 60.0);
  };
  ProcessResult r = run("stop");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run("status");
  EXPECT_NE(r.out.find("stopped: emergency stop"), std::string::npos) << r.out;
  r = run("home");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("HOME not run: rejected: stopped"), std::string::npos) << r.err;
  EXPECT_EQ(run("reset").exit_code, 0);
  r = run("home");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// An in-process backend (its counts are the ground truth), with one object, behind a relay the
// test controls.
robot::BackendOptions backendOptions(double speed, double watchdog_s, int port) {
  robot::BackendOptions options;
  options.speed_factor = speed;
  options.watchdog_s = watchdog_s;
  options.port = port;
  return options;
}
std::unique_ptr<robot::SimulatedArm> oneObjectArm() {
  robot::RobotConfig config;
  config.objects = {{4, {0.1, 0.6, 0.06}, 0.06, 0.03}};
  return std::make_unique<robot::SimulatedArm>(config);
}
robot::RunningBackend backendWith(const robot::Key& key, double speed, double watchdog_s = 0.1,
                                  int port = 0) {
  return robot::RunningBackend(oneObjectArm(), backendOptions(speed, watchdog_s, port), key);
}

// A fresh key file for one test (arbci robot keygen), and the key in it.
std::filesystem::path newKeyFile(const std::string& name) {
  const auto key_file = scratchPath(kScratch, name);
  const ProcessResult made = runProcess(kArbci, {"robot", "keygen", "--out", key_file.string()});
  EXPECT_EQ(made.exit_code, 0) << made.err;
  return key_file;
}

// `arbci robot [OPTIONS] grasp 0.1 0.6 0.06` to the relay's port, run in the background.
std::future<ProcessResult> graspThrough(const test::UdpRelay& relay,
                                        const std::filesystem::path& key_file,
                                        std::vector<std::string> options = {}) {
  std::vector<std::string> arguments = {"robot", "--port", std::to_string(relay.port()),
                                        "--key-file", key_file.string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  arguments.insert(arguments.end(), {"grasp", "0.1", "0.6", "0.06"});
  return std::async(std::launch::async,
                    [arguments] { return runProcess(kArbci, arguments, 60.0); });
}

// 100 commands in four lanes of 25 (a backend and a relay each, run side by side to save time).
TEST(RobotCommand, AtHalfTheDatagramsLostEachWayEveryCommandThatRanIsReportedAsRun) {
  const auto key_file = newKeyFile("lossy.key");
  const robot::Key key = robot::loadKey(key_file);
  struct Lane {
    Lane(const robot::Key& key, unsigned seed)
        : backend(backendWith(key, 50.0)), relay(backend.port(), key, seed) {
      relay.setLoss(0.5, 0.5);
    }
    robot::RunningBackend backend;
    test::UdpRelay relay;
    int reported_run = 0, reported_not_run = 0;
    std::string first_failure;
  };
  std::vector<std::unique_ptr<Lane>> lanes;
  for (unsigned seed = 1; seed <= 4; ++seed) lanes.push_back(std::make_unique<Lane>(key, seed));
  std::vector<std::thread> threads;
  for (auto& lane : lanes) {
    threads.emplace_back([&, l = lane.get()] {
      for (int i = 0; i < 25; ++i) {
        const ProcessResult r = runProcess(kArbci,
                                           {"robot", "--port", std::to_string(l->relay.port()),
                                            "--key-file", key_file.string(), "home"},
                                           60.0);
        const bool ran = r.exit_code == 0 || r.exit_code == 3;
        (ran ? l->reported_run : l->reported_not_run)++;
        if (!ran && l->first_failure.empty()) l->first_failure = r.err;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  std::uint64_t executed = 0, dropped = 0;
  int reported_run = 0;
  for (const auto& lane : lanes) {
    EXPECT_EQ(lane->backend.stats().executed, 25u) << lane->first_failure;  // each exactly once
    EXPECT_EQ(lane->reported_run, static_cast<int>(lane->backend.stats().executed))
        << lane->first_failure;
    executed += lane->backend.stats().executed;
    dropped += lane->relay.dropped();
    reported_run += lane->reported_run;
  }
  EXPECT_GT(dropped, 500u) << executed << " ran, " << reported_run << " reported as run";
}

TEST(RobotCommand, AMotionWhoseAnswersWereLostIsReportedAsRunAndStopped) {
  const auto key_file = newKeyFile("deaf.key");
  const robot::Key key = robot::loadKey(key_file);
  // Real time: the grasp takes seconds. The watchdog is not under test here: a generous one, so a
  // heartbeat starved on a loaded machine does not halt the grasp before the client's STOP.
  robot::RunningBackend backend = backendWith(key, 1.0, 5.0);
  test::UdpRelay relay(backend.port(), key);
  relay.dropReplies({robot::MessageType::Accepted, robot::MessageType::StatusReply,
                     robot::MessageType::Finished});
  auto cli = graspThrough(relay, key_file, {"--retry-budget", "1"});
  // Answers come back once the client has given up, which it shows by sending its STOP: the
  // STOP's answer and the status get through.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (relay.captured(robot::MessageType::Stop).empty() &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  relay.dropReplies({});
  const ProcessResult r = cli.get();
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("GRASP ran, but the answer was lost"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("STOP sent and accepted"), std::string::npos) << r.err;
  EXPECT_EQ(backend.stats().executed, 1u);
}

// Every answer lost from the moment the GRASP went out (a link that fails one way): the
// client cannot know whether it ran, and says so (exit 4); its STOP is not confirmed either.
TEST(RobotCommand, AMotionWhoseEveryAnswerIsLostIsReportedAsUnknown) {
  const auto key_file = newKeyFile("oneway.key");
  const robot::Key key = robot::loadKey(key_file);
  robot::RunningBackend backend = backendWith(key, 1.0, 5.0);
  test::UdpRelay relay(backend.port(), key);
  // The handshake gets through; nothing after it does.
  relay.dropReplies({robot::MessageType::Accepted, robot::MessageType::StatusReply,
                     robot::MessageType::Finished, robot::MessageType::Rejected});
  const ProcessResult r = graspThrough(relay, key_file, {"--retry-budget", "1"}).get();
  std::cout << r.err;
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("GRASP: unknown, it may have run"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("STOP sent but not confirmed"), std::string::npos) << r.err;
  EXPECT_EQ(backend.stats().executed, 1u);  // it did run: "not run" would have been a lie
}

// The backend restarts after the GRASP may have reached it, its acceptance lost: unknown (exit
// 4), with the arm's state as the new run reports it.
TEST(RobotCommand, AMotionLostInARestartIsReportedAsUnknownWithTheArmsState) {
  const auto key_file = newKeyFile("restart.key");
  const robot::Key key = robot::loadKey(key_file);
  auto backend =
      std::make_unique<robot::RunningBackend>(oneObjectArm(), backendOptions(1.0, 5.0, 0), key);
  const int port = backend->port();
  test::UdpRelay relay(port, key);
  relay.dropReplies({robot::MessageType::Accepted, robot::MessageType::StatusReply,
                     robot::MessageType::Finished});
  auto cli = graspThrough(relay, key_file);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (backend->stats().executed == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(backend->stats().executed, 1u);
  backend.reset();  // killed mid-grasp
  // Its last replies, already on their way, are lost too.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  relay.dropReplies({});
  robot::RunningBackend restarted = backendWith(key, 1.0, 5.0, port);
  const ProcessResult r = cli.get();
  std::cout << r.err;
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("the backend restarted"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("GRASP: unknown, it may have run"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the arm is stopped, holding nothing"), std::string::npos) << r.err;
  EXPECT_EQ(restarted.stats().executed, 0u);
}

// A GRASP from one shell held back by the network across `arbci robot stop` and `reset` from
// another: refused when it arrives, and the first shell says it did not run and why.
TEST(RobotCommand, AGraspHeldBackAcrossAStopAndResetNeverRuns) {
  const auto key_file = newKeyFile("held.key");
  const robot::Key key = robot::loadKey(key_file);
  robot::RunningBackend backend = backendWith(key, 50.0, 5.0);
  test::UdpRelay relay(backend.port(), key);
  relay.hold(robot::MessageType::Grasp);
  auto cli = graspThrough(relay, key_file);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (relay.captured(robot::MessageType::Grasp).empty() &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_FALSE(relay.captured(robot::MessageType::Grasp).empty());
  const std::vector<std::string> direct = {"robot", "--port", std::to_string(backend.port()),
                                           "--key-file", key_file.string()};
  auto with = [&](const char* command) {
    std::vector<std::string> arguments = direct;
    arguments.push_back(command);
    return runProcess(kArbci, arguments, 30.0);
  };
  ASSERT_EQ(with("stop").exit_code, 0);
  ASSERT_EQ(with("reset").exit_code, 0);
  // Every copy the first shell sent so far, then the rest as they come.
  for (const auto& bytes : relay.captured(robot::MessageType::Grasp)) {
    const robot::Decoded d = robot::decode(bytes.data(), bytes.size(), key);
    relay.release(d.message.sequence);
  }
  relay.stopHolding();
  const ProcessResult r = cli.get();
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("GRASP not run: rejected: made before a STOP"), std::string::npos) << r.err;
  EXPECT_EQ(backend.stats().executed, 0u);
}

}  // namespace
}  // namespace arbci::test
