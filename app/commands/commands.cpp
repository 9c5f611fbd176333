#include "commands/commands.h"

#include "robot_cli/robot_command.h"

namespace arbci::app {

void addCommands(CLI::App& root, int& exit_code) {
  addGlInfoCommand(root, exit_code);
  addScreenshotCommand(root, exit_code);
  addMarkerCommand(root, exit_code);
  addDetectCommand(root, exit_code);
  addCalibrateCommand(root, exit_code);
  addEegCommand(root, exit_code);
  addP300Commands(root, exit_code);
  addRobotCommand(root, exit_code);
  addBidsCommand(root, exit_code);
  addRunCommand(root, exit_code);
  addTimingCheckCommand(root, exit_code);
  addSettingsCommand(root, exit_code);
  addLogEventsCommand(root, exit_code);
}

}  // namespace arbci::app
