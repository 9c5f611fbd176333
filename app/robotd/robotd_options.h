// arbci-robotd's command line: where it listens, its key, the arm it drives and how, each option
// that sets a settings key made from the key (support/schema_option.h).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace arbci::app {

struct RobotdOptions {
  int port = 0;  // robot.port
  std::string host, key_file, config_file, port_file, model;
  std::string driver;  // robot.driver
  double speed = 0.0;  // 0: the config's speed_factor
  bool stepped = false;
  int watchdog_ms = 0;  // robot.watchdog_ms
};

void addRobotdOptions(CLI::App& app, RobotdOptions& o);

}  // namespace arbci::app
