#include "arbci/session/robot_connection.h"

#include <fstream>

#include "arbci/robot/key_file.h"

namespace arbci::session {

void checkRobotKey(const RobotSettings& settings, const std::string& session_file) {
  if (!settings.key_file.empty() && !std::filesystem::exists(settings.key_file))
    throw SessionConfigError(session_file + ": robot.key_file = \"" + settings.key_file +
                             "\": no such file");
}

RobotLink connectRobot(const RobotSettings& settings, const robot::RobotConfig& simulated_world,
                       const std::filesystem::path& folder, const Clock& clock) {
  RobotLink link;
  if (settings.backend != "simulated") {
    link.client = std::make_unique<robot::RobotClient>(
        robot::Endpoint::resolve(settings.host, settings.port), robot::loadKey(settings.key_file));
    return link;
  }
  const robot::Key key = robot::generateKey();
  const auto key_file = folder / "robot.key";
  robot::saveKey(key_file, key);
  robot::RobotConfig config = simulated_world;
  config.model = settings.model;
  std::ofstream(folder / "robot.json") << config.toJson();
  // A simulated clock steps the arm too (the robot follows the session, frame by frame).
  link.stepped = clock.stepped();
  link.backend = std::make_unique<RobotProcess>(robotdNextToMe(), key_file, folder / "robot.json",
                                                settings.driver, settings.speed_factor,
                                                settings.watchdog_ms, folder, link.stepped);
  std::ofstream(folder / "robotd.pid") << link.backend->pid() << "\n";
  link.client = std::make_unique<robot::RobotClient>(
      robot::Endpoint::resolve("127.0.0.1", link.backend->port()), key);
  return link;
}

}  // namespace arbci::session
