// hmd.output "openxr" with the OpenXR loader and no runtime: a headless run fails its pre-flight
// naming the cause and the runtime's result code, before any flash, and says so at the end.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/run_process.h"

namespace arbci::test {
namespace {

TEST(OpenXrOutput, WithoutARuntimeTheRunFailsItsPreflightNamingTheCause) {
  const auto dir = std::filesystem::temp_directory_path() / "arbci_openxr_cli_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto session = dir / "session.json";
  std::ofstream(session) << R"({"hmd": {"output": "openxr"}})";
  // The loader is told of a runtime that is not there (whatever the machine has installed).
  ::setenv("XR_RUNTIME_JSON", (dir / "no_runtime.json").c_str(), 1);
  const auto folder = dir / "run";
  const ProcessResult r = runProcess(
      ARBCI_EXECUTABLE,
      {"run", "--headless", "--session", session.string(), "--out", folder.string()}, 120.0);
  ::unsetenv("XR_RUNTIME_JSON");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("hmd.output = openxr"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("XR_ERROR_"), std::string::npos) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(folder / "summary.json"));
  const std::string reason = summary["end_reason"].get<std::string>();
  EXPECT_NE(reason.find("hmd.output = openxr"), std::string::npos) << reason;
  // Nothing was flashed: the run ended before its calibration.
  EXPECT_EQ(summary["timing"]["flash_ms"]["count"], 0) << summary["timing"];
}

}  // namespace
}  // namespace arbci::test
