// An error a command reports to the user as one line, with the process's exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace arbci::app {

class CliError : public std::runtime_error {
 public:
  explicit CliError(const std::string& message, int exit_code = 1)
      : std::runtime_error(message), exit_code_(exit_code) {}
  int exitCode() const { return exit_code_; }

 private:
  int exit_code_;
};

}  // namespace arbci::app
