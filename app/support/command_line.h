// How an `arbci` executable runs its command line: the commands added to `root` parsed, help when
// none is given, and every error one line naming the command's --help ("arbci: ... (see arbci eeg
// convert --help)") with its exit code. Shared by the front door (app/main.cpp) and the
// workstation's executable (app/workstation_main.cpp).
#pragma once

#include <CLI/CLI.hpp>

namespace arbci::app {

// `exit_code`: what the command that ran set (the commands' callbacks set it).
int runCommandLine(CLI::App& root, int argc, char** argv, const int& exit_code);

}  // namespace arbci::app
