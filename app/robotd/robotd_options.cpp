#include "robotd/robotd_options.h"

#include "arbci/robot/settings.h"
#include "support/schema_option.h"

namespace arbci::app {

void addRobotdOptions(CLI::App& app, RobotdOptions& o) {
  const auto& link = robot::linkSchema();
  // Not robot.port's option: a backend may listen on any free port (0), a session cannot
  // connect to one.
  o.port = robot::LinkSettings().port;
  app.add_option("--port", o.port, "UDP port to listen on (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  app.add_option("--port-file", o.port_file,
                 "write the port listened on to this file once listening");
  schemaOption(app, "--host", o.host, link.at("host"), "the address to listen on");
  app.add_option("--key-file", o.key_file, "the shared key")->required();
  schemaOption(app, "--driver", o.driver, link.at("driver"));
  schemaOption(app, "--model", o.model, robot::configSchema().at("model"),
               "in place of the config's model");
  app.add_option("--config", o.config_file,
                 "ROBOT.json: workspace, table, motion, simulated objects (defaults if omitted)");
  schemaOptionOwnDefault(app, "--speed", o.speed, robot::configSchema().at("speed_factor"), 0.0,
                         "the config's speed_factor");
  app.add_flag("--stepped", o.stepped,
               "move the arm only when a STATUS carries the client's clock (reproducible "
               "simulations: arbci run headless starts it so), never on the wall clock");
  schemaOption(app, "--watchdog-ms", o.watchdog_ms, link.at("watchdog_ms"));
}

}  // namespace arbci::app
