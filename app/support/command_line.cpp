#include "support/command_line.h"

#include <exception>
#include <iostream>
#include <string>

#include "support/cli_error.h"
#include "support/status_line.h"

namespace arbci::app {
namespace {

// The command the user gave, as far as it was parsed: "arbci eeg convert".
std::string commandPath(const CLI::App& root) {
  std::string path = "arbci";
  const CLI::App* app = &root;
  while (app) {
    const auto chosen = app->get_subcommands();
    app = chosen.empty() ? nullptr : chosen.front();
    if (app) path += " " + app->get_name();
  }
  return path;
}

}  // namespace

int runCommandLine(CLI::App& root, int argc, char** argv, const int& exit_code) {
  root.set_version_flag("--version", std::string("arbci ") + ARBCI_VERSION);
  root.require_subcommand(0, 1);
  // Every error points to the help of the command that failed.
  root.failure_message([&root](const CLI::App*, const CLI::Error& error) {
    return std::string("arbci: ") + error.what() + " (see " + commandPath(root) + " --help)\n";
  });
  try {
    root.parse(argc, argv);
    if (root.get_subcommands().empty()) {
      std::cout << root.help();
      return 0;
    }
  } catch (const CLI::ParseError& error) {
    return root.exit(error);
  } catch (const CliError& error) {
    if (statusLineOpen()) std::cerr << "\n";  // not over a progress line
    std::cerr << "arbci: " << error.what() << " (see " << commandPath(root) << " --help)\n";
    return error.exitCode();
  } catch (const std::exception& error) {
    if (statusLineOpen()) std::cerr << "\n";
    std::cerr << "arbci: " << error.what() << " (see " << commandPath(root) << " --help)\n";
    return 1;
  }
  return exit_code;
}

}  // namespace arbci::app
