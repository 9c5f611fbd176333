// The README's command summary cannot go stale: every command line in its "## Commands" block
// names a subcommand that exists, and every option it shows is one that subcommand's --help
// lists (the README once showed `arbci marker train IMAGE` for a command that wants --image).
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "support/run_process.h"

namespace arbci::test {
namespace {

struct Synopsis {
  std::string program;             // arbci or arbci-robotd
  std::vector<std::string> chain;  // the subcommands, e.g. {"eeg", "convert"}
  std::vector<std::string> options;
  std::vector<std::string> after;  // what the synopsis shows after each option ("" at its end)
  std::string line;
};

// The block after "## Commands": each line that starts with a program name begins a command; an
// indented line that starts with [ or -- continues it; other indented lines are descriptions.
std::vector<Synopsis> readmeCommands() {
  std::ifstream in(std::string(ARBCI_SOURCE_DIR) + "/README.md");
  std::string line;
  bool in_section = false, in_block = false;
  std::vector<Synopsis> out;
  const std::regex option("--[a-z][a-z0-9-]*");
  auto addOptions = [&](const std::string& text, Synopsis& s) {
    // The synopsis ends where two spaces start its description.
    const std::string synopsis = text.substr(0, text.find("  "));
    for (std::sregex_iterator it(synopsis.begin(), synopsis.end(), option), end; it != end; ++it) {
      s.options.push_back(it->str());
      std::istringstream rest(synopsis.substr(static_cast<size_t>(it->position() + it->length())));
      std::string next;
      rest >> next;
      s.after.push_back(next);
    }
  };
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## Commands";
    if (!in_section) continue;
    if (line.rfind("```", 0) == 0) {
      in_block = !in_block;
      continue;
    }
    if (!in_block || line.empty()) continue;
    if (line.rfind("arbci", 0) == 0) {
      Synopsis s;
      s.line = line;
      std::istringstream words(line);
      words >> s.program;
      std::string word;
      while (words >> word && std::regex_match(word, std::regex("[a-z][a-z0-9-]*")))
        s.chain.push_back(word);
      addOptions(line, s);
      out.push_back(s);
    } else if (!out.empty()) {
      const std::string trimmed = line.substr(line.find_first_not_of(' '));
      if (trimmed[0] == '[' || trimmed.rfind("--", 0) == 0) addOptions(trimmed, out.back());
    }
  }
  return out;
}

TEST(Readme, EveryCommandAndOptionInTheCommandSummaryExists) {
  const std::vector<Synopsis> commands = readmeCommands();
  ASSERT_GE(commands.size(), 15u) << "the README's ## Commands block was not found";
  for (const Synopsis& s : commands) {
    const std::string program =
        s.program == "arbci-robotd" ? ARBCI_ROBOTD_EXECUTABLE : ARBCI_EXECUTABLE;
    std::vector<std::string> arguments = s.chain;
    arguments.push_back("--help");
    const ProcessResult help = runProcess(program, arguments, 30.0);
    ASSERT_EQ(help.exit_code, 0) << s.line << "\n" << help.err;
    for (size_t k = 0; k < s.options.size(); ++k) {
      const std::string& option = s.options[k];
      EXPECT_NE(help.out.find(option), std::string::npos) << "README: " << s.line << "\n"
                                                          << option << " is not in its --help:\n"
                                                          << help.out;
      // An option that takes a value (its --help shows TEXT, INT, FLOAT ...) is shown with one:
      // `--pose` alone would be refused by the command (the README once showed it so).
      const std::regex takes_value(option + "( [A-Z]+|,[^ ]* [A-Z]+)");
      const std::string& next = s.after[k];
      if (std::regex_search(help.out, takes_value)) {
        EXPECT_FALSE(next.empty() || next.rfind("--", 0) == 0 || next[0] == ']' || next[0] == '|')
            << "README: " << s.line << "\n"
            << option << " needs a value but is shown without one";
      }
    }
  }
}

}  // namespace
}  // namespace arbci::test
