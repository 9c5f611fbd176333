// The robot module's settings table (the backend's ROBOT.json) and its registry of drivers:
// arbci-robotd --driver NAME drives robotDrivers()'s NAME with the configuration read through
// configSchema() (docs/robot.md). Adding a driver is a file in robot/src/drivers/ and a line in
// its registry.cpp.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "arbci/core/registry.h"
#include "arbci/core/schema.h"
#include "arbci/robot/robot_config.h"
#include "arbci/robot/robot_driver.h"

namespace arbci::robot {

const core::Schema<RobotConfig>& configSchema();
// An object of the simulated world (configSchema()'s objects[]).
const core::Schema<SimulatedObject>& objectSchema();

// Where a backend listens and a client finds it.
struct LinkSettings {
  LinkSettings();  // linkSchema()'s defaults
  std::string host;
  int port;
  int watchdog_ms;
  std::string driver;    // the arm arbci-robotd drives: robotDrivers()'s name
  std::string key_file;  // the shared key a client authenticates with
};
const core::Schema<LinkSettings>& linkSchema();
// Its keys a client needs (host, port, watchdog_ms, key_file), without the drivers' registry.
const core::Schema<LinkSettings>& clientLinkSchema();

struct DriverParts {
  // Throws std::runtime_error with the reason when the arm cannot be driven.
  std::function<std::unique_ptr<RobotDriver>(const RobotConfig& config)> make;
};
using DriverRegistry = core::Registry<DriverParts>;
const DriverRegistry& robotDrivers();

}  // namespace arbci::robot
