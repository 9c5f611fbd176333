// Parses marker id lists as given on the command line: "7", "0-11", "1,4,9-12".
#pragma once

#include <string>
#include <vector>

namespace arbci::app {

// Throws CliError naming the bad part; ids must lie in [0, max_id].
std::vector<int> parseIdList(const std::string& text, int max_id);

}  // namespace arbci::app
