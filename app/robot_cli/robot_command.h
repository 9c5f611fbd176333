// `arbci robot`: keygen, and status, home, stop, reset, grasp, drop against a backend. Its own
// small library (the robot client, CLI11 and the schema's options only), so that `arbci robot
// stop` starts in milliseconds: the `arbci` executable runs it without loading GL, OpenCV or
// MuJoCo (app/main.cpp), and the workstation's executable lists it with every other command.
#pragma once

#include <CLI/CLI.hpp>

namespace arbci::app {

void addRobotCommand(CLI::App& root, int& exit_code);

}  // namespace arbci::app
