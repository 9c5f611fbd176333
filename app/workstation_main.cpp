// arbci-workstation: the experimenter workstation and every batch command (app/main.cpp, the
// `arbci` executable, starts it for all but `arbci robot`).
#include <CLI/CLI.hpp>

#include "commands/commands.h"
#include "support/command_line.h"

int main(int argc, char** argv) {
  CLI::App root{
      "ARBCI: augmented-reality BCI experimenter workstation.\n"
      "Markers, EEG, P300 classification and a robot arm, in one cycle.",
      "arbci"};
  int exit_code = 0;
  arbci::app::addCommands(root, exit_code);
  return arbci::app::runCommandLine(root, argc, argv, exit_code);
}
