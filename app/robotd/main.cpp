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
#include "robotd/robotd_options.h"

namespace {

std::atomic<bool> stop_requested{false};

void onSignal(int) {
  stop_requested = true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string about =
      "arbci-robotd: the ARBCI robot backend. Accepts HELLO, BIND, GRASP, DROP, HOME, STOP, "
      "RESET, HEARTBEAT and STATUS over UDP,\nauthenticated with the shared key (make one with "
      "`arbci robot keygen`), and drives an arm (--driver):\n" +
      arbci::robot::robotDrivers().describe() +
      "Protocol: docs/robot-protocol.md; the drivers and the physics arm's model: docs/robot.md.";
  CLI::App app{about, "arbci-robotd"};
  arbci::app::RobotdOptions o;
  arbci::app::addRobotdOptions(app, o);
  app.set_version_flag("--version", std::string("arbci-robotd ") + ARBCI_VERSION);
  app.failure_message([](const CLI::App*, const CLI::Error& error) {
    return std::string("arbci-robotd: ") + error.what() + "\n";
  });
  CLI11_PARSE(app, argc, argv);

  try {
    const arbci::robot::Key key = arbci::robot::loadKey(o.key_file);
    arbci::robot::RobotConfig config;
    if (!o.config_file.empty()) config = arbci::robot::RobotConfig::load(o.config_file);
    if (!o.model.empty()) config.model = o.model;
    arbci::robot::BackendOptions options;
    options.port = o.port;
    options.host = o.host;
    options.speed_factor = o.speed > 0.0 ? o.speed : config.speed_factor;
    options.log = &std::cerr;
    options.stepped = o.stepped;
    options.watchdog_s = o.watchdog_ms / 1000.0;
    arbci::robot::RobotBackend backend(
        key, arbci::robot::robotDrivers().at(o.driver).make.make(config), options);
    if (!o.port_file.empty()) {
      std::ofstream out(o.port_file);
      out << backend.port() << "\n";
      if (!out) throw std::runtime_error("cannot write " + o.port_file);
    }
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    // A motion controller's loop: a busy PC must not delay a STOP or the watchdog's halt.
    const std::string priority = arbci::robot::raiseThreadPriority();
    std::cerr << "arbci-robotd: listening on " << o.host << ":" << backend.port() << " ("
              << o.driver << " arm, speed x" << options.speed_factor << ", "
              << config.objects.size() << " objects, watchdog "
              << (o.stepped           ? std::string("off (stepped)")
                  : o.watchdog_ms > 0 ? std::to_string(o.watchdog_ms) + " ms"
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
