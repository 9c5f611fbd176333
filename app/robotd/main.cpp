// arbci-robotd: the robot backend. Listens for authenticated commands on UDP and drives the
// simulated arm (the default driver) in real time or faster.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>

#include "arbci/robot/backend.h"
#include "arbci/robot/key_file.h"
#include "arbci/robot/robot_config.h"
#include "arbci/robot/settings.h"
#include "arbci/robot/simulated_arm.h"
#include "arbci/robot/thread_priority.h"

namespace {

std::atomic<bool> stop_requested{false};

void onSignal(int) {
  stop_requested = true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "arbci-robotd: the ARBCI robot backend. Accepts HELLO, GRASP, DROP, HOME, STOP, RESET, "
      "HEARTBEAT and STATUS over UDP,\n"
      "authenticated with the shared key (make one with `arbci robot keygen`), and drives a\n"
      "simulated six-joint arm (UR10 kinematics) over a simulated table. Protocol: "
      "docs/robot-protocol.md.",
      "arbci-robotd"};
  const arbci::robot::LinkSettings link;  // the defaults a session's robot section has
  int port = link.port;
  std::string host = link.host, key_file, config_file, port_file, driver = "simulated";
  double speed = 0.0;
  bool stepped = false;
  int watchdog_ms = link.watchdog_ms;
  app.add_option("--port", port, "UDP port to listen on (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--port-file", port_file,
                 "write the port listened on to this file once listening");
  app.add_option("--host", host, "address to listen on (127.0.0.1: this machine only)")
      ->capture_default_str();
  app.add_option("--key-file", key_file, "the shared key")->required();
  app.add_option("--driver", driver, "the arm to drive: " + arbci::robot::robotDrivers().list(", "))
      ->capture_default_str()
      ->check(CLI::IsMember(arbci::robot::robotDrivers().names()));
  app.add_option("--config", config_file,
                 "ROBOT.json: workspace, table, motion, simulated objects (defaults if omitted)");
  app.add_option("--speed", speed,
                 "simulated seconds per real second (overrides the config's speed_factor)")
      ->check(CLI::Range(0.01, 1000.0));
  app.add_flag("--stepped", stepped,
               "move the arm only when a STATUS carries the client's clock (reproducible "
               "simulations: arbci run headless starts it so), never on the wall clock");
  app.add_option("--watchdog-ms", watchdog_ms, arbci::robot::linkSchema().at("watchdog_ms").doc)
      ->capture_default_str()
      ->check(CLI::Range(0, 60000));
  app.set_version_flag("--version", std::string("arbci-robotd ") + ARBCI_VERSION);
  app.failure_message([](const CLI::App*, const CLI::Error& error) {
    return std::string("arbci-robotd: ") + error.what() + "\n";
  });
  CLI11_PARSE(app, argc, argv);

  try {
    const arbci::robot::Key key = arbci::robot::loadKey(key_file);
    arbci::robot::RobotConfig config;
    if (!config_file.empty()) config = arbci::robot::RobotConfig::load(config_file);
    arbci::robot::BackendOptions options;
    options.port = port;
    options.host = host;
    options.speed_factor = speed > 0.0 ? speed : config.speed_factor;
    options.log = &std::cerr;
    options.stepped = stepped;
    options.watchdog_s = watchdog_ms / 1000.0;
    arbci::robot::RobotBackend backend(
        key, arbci::robot::robotDrivers().at(driver).make.make(config), options);
    if (!port_file.empty()) {
      std::ofstream out(port_file);
      out << backend.port() << "\n";
      if (!out) throw std::runtime_error("cannot write " + port_file);
    }
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    // A motion controller's loop: a busy PC must not delay a STOP or the watchdog's halt.
    const std::string priority = arbci::robot::raiseThreadPriority();
    std::cerr << "arbci-robotd: listening on " << host << ":" << backend.port() << " (" << driver
              << " arm, speed x" << options.speed_factor << ", " << config.objects.size()
              << " objects, watchdog "
              << (stepped           ? std::string("off (stepped)")
                  : watchdog_ms > 0 ? std::to_string(watchdog_ms) + " ms"
                                    : "off")
              << ", receive buffer " << backend.receiveBufferBytes() / 1024 << " KiB, scheduling "
              << priority << ")" << std::endl;
    if (backend.receiveBufferBytes() < options.receive_buffer_bytes)
      std::cerr << "arbci-robotd: the kernel granted a smaller receive buffer than the "
                << options.receive_buffer_bytes / 1024
                << " KiB asked; a burst of datagrams may crowd out commands (raise "
                   "net.core.rmem_max)"
                << std::endl;
    backend.run(stop_requested);
    const arbci::robot::BackendStats s = backend.stats();
    std::cerr << "arbci-robotd: stopped; " << s.datagrams << " datagrams, " << s.executed
              << " commands run, " << s.rejected << " rejected, " << s.replayed << " replayed, "
              << s.ignored << " ignored, " << s.shed << " shed unread, " << s.watchdog_halts
              << " watchdog halts" << std::endl;
  } catch (const std::exception& error) {
    std::cerr << "arbci-robotd: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
