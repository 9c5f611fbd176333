// arbci: the command line's front door. `arbci robot ...` runs here, in an executable that loads
// no GL, OpenCV or MuJoCo: a STOP typed in a fresh shell on a busy machine starts in milliseconds,
// not in the second or more that loading the workstation's libraries takes. Every other command
// is the workstation's executable beside this one (arbci-workstation), started in this process's
// place (the same process id, arguments and environment).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>

#include "robot_cli/robot_command.h"
#include "support/command_line.h"

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "robot") {
    CLI::App root{"ARBCI: the robot backend from the shell.", "arbci"};
    int exit_code = 0;
    arbci::app::addRobotCommand(root, exit_code);
    return arbci::app::runCommandLine(root, argc, argv, exit_code);
  }
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path workstation = self.parent_path() / "arbci-workstation";
  ::execv(workstation.c_str(), argv);
  std::cerr << "arbci: cannot start " << workstation.string() << " (" << std::strerror(errno)
            << "): it is built beside arbci (cmake --build --preset release)\n";
  return 127;
}
