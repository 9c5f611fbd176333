// The log's events are declared once (session/src/log_events.cpp): every event the sources write
// is declared there, every declared one is written somewhere, and docs/log.md is the table
// `arbci log-events` prints.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "arbci/session/log_events.h"

namespace arbci::session {
namespace {

const std::filesystem::path kSource = ARBCI_SOURCE_DIR;

std::string text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// The names passed to a session log's write() ("log_->write(", "s_.log.write(", ...) in every
// source file of the modules that write the log.
std::set<std::string> writtenEvents() {
  const std::regex write(R"((?:log_?|s_\.log|log\(\))\s*(?:->|\.)\s*write\(\s*"([^"]+)\")");
  std::set<std::string> names;
  for (const char* module : {"session", "app", "bci", "robot", "ui"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(kSource / module)) {
      if (entry.path().extension() != ".cpp") continue;
      const std::string source = text(entry.path());
      for (std::sregex_iterator m(source.begin(), source.end(), write), end; m != end; ++m)
        names.insert((*m)[1].str());
    }
  }
  return names;
}

TEST(LogEvents, EveryEventWrittenIsDeclaredAndEveryDeclaredOneIsWritten) {
  const std::set<std::string> written = writtenEvents();
  ASSERT_GT(written.size(), 50u);  // the pattern still finds the writes
  std::set<std::string> declared;
  for (const LogEvent& e : logEvents()) {
    EXPECT_TRUE(declared.insert(std::string(e.name)).second) << e.name << " declared twice";
    EXPECT_FALSE(e.meaning.empty()) << e.name;
  }
  for (const std::string& name : written)
    EXPECT_TRUE(declared.count(name)) << "\"" << name << "\" is written but not declared";
  for (const std::string& name : declared)
    EXPECT_TRUE(written.count(name)) << "\"" << name << "\" is declared but never written";
  EXPECT_EQ(findLogEvent("hmd_frame")->fields, "frame, display_s, submitted_s, lead_ms, head");
  EXPECT_EQ(findLogEvent("no_such_event"), nullptr);
}

TEST(LogEvents, DocsLogIsTheDeclaredTable) {
  const std::string docs = text(kSource / "docs/log.md");
  EXPECT_NE(docs.find(logEventsMarkdown()), std::string::npos)
      << "docs/log.md is not the declared table: print it again with `arbci log-events > "
         "docs/log.md`";
}

}  // namespace
}  // namespace arbci::session
