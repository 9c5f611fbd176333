// A session's folder is never overwritten by accident: a folder holding a session is refused
// (its data untouched), --overwrite empties it, a failed pre-flight's folder is taken by a retry,
// and a start that fails leaves nothing behind.
#include <gtest/gtest.h>

#include <fstream>

#include "support/cli_error.h"
#include "support/session_folder.h"
#include "support/test_files.h"

namespace arbci::app {
namespace {

TEST(SessionFolder, AFolderHoldingASessionIsRefusedAndKeptAsItWas) {
  const auto folder = test::freshTempPath("session_folder", "taken");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "summary.json") << "{\"ended\": \"finished\"}\n";
  try {
    claimFolder(folder.string(), false);
    FAIL() << "a folder holding a session was taken";
  } catch (const CliError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("exists and is not empty"), std::string::npos) << what;
    EXPECT_NE(what.find("--overwrite"), std::string::npos) << what;
  }
  EXPECT_TRUE(std::filesystem::exists(folder / "summary.json"));
  claimFolder(folder.string(), true);
  EXPECT_FALSE(std::filesystem::exists(folder));
}

TEST(SessionFolder, AFailedPreflightsFolderIsTakenByARetry) {
  const auto folder = test::freshTempPath("session_folder", "failed_preflight");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "summary.json")
      << "{\"ended\": \"aborted\", \"end_reason\": \"pre-flight failed: robot.host, "
         "robot.port: no answer\", \"trials\": []}\n";
  EXPECT_TRUE(holdsOnlyAFailedStart(folder));
  claimFolder(folder.string(), false);
  EXPECT_FALSE(std::filesystem::exists(folder));
}

TEST(SessionFolder, AFailedStartLeavesNothingBehind) {
  const auto fresh = test::freshTempPath("session_folder", "fresh");
  {
    FolderClaim claim(fresh);
    std::filesystem::create_directories(fresh);
    std::ofstream(fresh / "log.jsonl") << "{}\n";
  }
  EXPECT_FALSE(std::filesystem::exists(fresh));
  // A folder given empty is left empty.
  const auto empty = test::freshTempPath("session_folder", "empty");
  std::filesystem::create_directories(empty);
  {
    FolderClaim claim(empty);
    std::ofstream(empty / "log.jsonl") << "{}\n";
  }
  EXPECT_TRUE(std::filesystem::is_empty(empty));
  // Once the session has opened the folder is its.
  {
    FolderClaim claim(empty);
    std::ofstream(empty / "log.jsonl") << "{}\n";
    claim.keep();
  }
  EXPECT_TRUE(std::filesystem::exists(empty / "log.jsonl"));
}

}  // namespace
}  // namespace arbci::app
