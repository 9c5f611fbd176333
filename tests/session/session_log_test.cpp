// The session's log on a disk that fills: a line the system cannot take is cut back off the file
// (a JSON-lines reader never meets half a line), counted and told once; the log resumes when
// there is room, its first line saying how many were lost. Real files: /dev/full, and a file
// held to a size limit (RLIMIT_FSIZE) that is then lifted.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/session/session_log.h"
#include "support/file_size_limit.h"

namespace arbci::session {
namespace {

std::vector<nlohmann::json> linesOf(const std::filesystem::path& path) {
  std::vector<nlohmann::json> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

TEST(SessionLog, WritesOneJsonObjectPerLine) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "log_plain.jsonl";
  {
    SessionLog log(path);
    log.write("session_started", 0.0, {{"seed", 1}});
    log.write("cycle", 0.1);
    EXPECT_EQ(log.lost(), 0);
    EXPECT_EQ(log.news(), "");
  }
  const auto lines = linesOf(path);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0]["event"], "session_started");
  EXPECT_EQ(lines[0]["seed"], 1);
  EXPECT_EQ(lines[1]["t"], 0.1);
}

TEST(SessionLog, OnAFullDiskLinesAreCountedAndTheFailureToldOnce) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  SessionLog log("/dev/full");
  log.write("cycle", 0.1);
  EXPECT_TRUE(log.failing());
  const std::string news = log.news();
  EXPECT_NE(news.find("cannot write"), std::string::npos) << news;
  EXPECT_NE(news.find(std::strerror(ENOSPC)), std::string::npos) << news;
  log.write("cycle", 0.2);
  EXPECT_EQ(log.news(), "");  // told once
  EXPECT_EQ(log.lost(), 2);
}

TEST(SessionLog, KeepsWholeLinesWhenFullAndResumesWithTheCountLost) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "log_limited.jsonl";
  std::filesystem::remove(path);
  SessionLog log(path);
  const nlohmann::json fields = {{"text", std::string(40, 'x')}};
  {
    const test::FileSizeLimit limit(300);
    for (int i = 0; i < 10; ++i) log.write("note", 0.1 * i, fields);
  }
  EXPECT_TRUE(log.failing());
  const int lost = log.lost();
  EXPECT_GT(lost, 0);
  EXPECT_LT(lost, 10);
  EXPECT_NE(log.news().find(std::strerror(EFBIG)), std::string::npos);
  // Only whole lines in the file, up to the limit.
  const auto kept = linesOf(path);
  EXPECT_EQ(static_cast<int>(kept.size()), 10 - lost);
  EXPECT_LE(std::filesystem::file_size(path), 300u);
  // Room again: the gap is said, then the line.
  log.write("note", 5.0, fields);
  EXPECT_FALSE(log.failing());
  const std::string news = log.news();
  EXPECT_NE(news.find("writing again; " + std::to_string(lost)), std::string::npos) << news;
  const auto lines = linesOf(path);
  ASSERT_EQ(lines.size(), kept.size() + 2);
  EXPECT_EQ(lines[kept.size()]["event"], "log_lines_lost");
  EXPECT_EQ(lines[kept.size()]["lines"], lost);
  EXPECT_EQ(lines.back()["t"], 5.0);
  EXPECT_EQ(log.lost(), lost);
}

}  // namespace
}  // namespace arbci::session
