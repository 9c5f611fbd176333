// Each subcommand of `arbci` registers itself on the root CLI11 app. A command's callback stores
// its exit code in `exit_code`; errors are thrown as CliError.
#pragma once

#include <CLI/CLI.hpp>

namespace arbci::app {

// Every subcommand, in the order `arbci --help` lists them.
void addCommands(CLI::App& root, int& exit_code);

void addGlInfoCommand(CLI::App& root, int& exit_code);
void addScreenshotCommand(CLI::App& root, int& exit_code);
void addMarkerCommand(CLI::App& root, int& exit_code);
void addDetectCommand(CLI::App& root, int& exit_code);
void addCalibrateCommand(CLI::App& root, int& exit_code);
void addEegCommand(CLI::App& root, int& exit_code);
void addEegStreamCommands(CLI::App* eeg, int& exit_code);  // stream, streams (under eeg)
void addP300Commands(CLI::App& root, int& exit_code);      // train, evaluate
void addRunCommand(CLI::App& root, int& exit_code);
void addTimingCheckCommand(CLI::App& root, int& exit_code);
void addSettingsCommand(CLI::App& root, int& exit_code);
void addLogEventsCommand(CLI::App& root, int& exit_code);  // docs/log.md
void addBidsCommand(CLI::App& root, int& exit_code);

}  // namespace arbci::app
