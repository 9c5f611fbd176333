// Runs a program with arguments and captures its exit code, stdout and stderr (tests only).
#pragma once

#include <string>
#include <vector>

namespace arbci::test {

struct ProcessResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// Runs `program` with `arguments` in a process group of its own, killing the group (what it
// started too) after `timeout_seconds`; output still held open 5 s later is not waited for.
ProcessResult runProcess(const std::string& program, const std::vector<std::string>& arguments,
                         double timeout_seconds = 120.0);

}  // namespace arbci::test
