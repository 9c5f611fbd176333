// hmd.output "openxr" with the OpenXR loader and no runtime: a run, headless (EGL) or in a window
// (GLX, under Xvfb), fails its pre-flight naming the cause and the runtime's result code, before
// any flash, and says so at the end.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/run_process.h"
#include "support/xvfb_server.h"

namespace arbci::test {
namespace {

// The run's folder after `arbci run ARGUMENTS --session S --out FOLDER` with hmd.output openxr and
// the loader told of a runtime that is not there (whatever the machine has installed), run by
// `launcher` (env, with the window's DISPLAY where there is one).
struct Refused {
  ProcessResult process;
  std::string end_reason;
  nlohmann::json timing;
};
Refused runWithoutRuntime(const std::string& name, std::vector<std::string> prefix,
                          std::vector<std::string> arguments) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("arbci_openxr_cli_test_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto session = dir / "session.json";
  std::ofstream(session) << R"({"hmd": {"output": "openxr"}})";
  const auto folder = dir / "run";
  prefix.push_back("XR_RUNTIME_JSON=" + (dir / "no_runtime.json").string());
  prefix.push_back(ARBCI_EXECUTABLE);
  prefix.push_back("run");
  for (const std::string& a : arguments) prefix.push_back(a);
  for (const std::string& a :
       {std::string("--session"), session.string(), std::string("--out"), folder.string()})
    prefix.push_back(a);
  Refused r;
  r.process = runProcess("/usr/bin/env", prefix, 120.0);
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(folder / "summary.json"));
  r.end_reason = summary["end_reason"].get<std::string>();
  r.timing = summary["timing"];
  return r;
}

void expectRefused(const Refused& r) {
  EXPECT_EQ(r.process.exit_code, 3) << r.process.err;
  EXPECT_NE(r.end_reason.find("pre-flight failed: hmd.output = openxr: OpenXR: no runtime"),
            std::string::npos)
      << r.end_reason;
  EXPECT_NE(r.end_reason.find("XR_ERROR_"), std::string::npos) << r.end_reason;
  // Nothing was flashed: the run ended before its calibration.
  EXPECT_EQ(r.timing["flash_ms"]["count"], 0) << r.timing;
}

TEST(OpenXrOutput, WithoutARuntimeTheRunFailsItsPreflightNamingTheCause) {
  const Refused r = runWithoutRuntime("headless", {}, {"--headless"});
  expectRefused(r);
  EXPECT_NE(r.process.err.find("hmd.output = openxr"), std::string::npos) << r.process.err;
}

TEST(OpenXrOutput, InAWindowWithoutARuntimeTheRunFailsItsPreflightNamingTheCause) {
  const XvfbServer x;
  expectRefused(runWithoutRuntime("window", {"-u", "XAUTHORITY", "DISPLAY=" + x.display()},
                                  {"--start-now", "--exit-when-done"}));
}

}  // namespace
}  // namespace arbci::test
