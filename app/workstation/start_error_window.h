// A windowed run whose session cannot start: the window opens anyway and says why
// (ui/start_error_screen.h), until the experimenter quits. A scripted experimenter (--script)
// can take its screenshot and press Quit as in the workstation.
#pragma once

#include <filesystem>
#include <string>

namespace arbci::app {

// Returns once the window is closed or Quit pressed; false when no window could be opened (the
// message then stands on the terminal alone) or the script failed.
bool showStartError(const std::string& message, const std::filesystem::path& script);

}  // namespace arbci::app
