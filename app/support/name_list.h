// Comma-separated names as given on the command line ("Fz,Cz,Pz"), split (empty ones dropped)
// and joined for messages.
#pragma once

#include <string>
#include <vector>

namespace arbci::app {

std::vector<std::string> splitNameList(const std::string& text);
// The other way: "Fz, Cz, Pz".
std::string joinNames(const std::vector<std::string>& names);

}  // namespace arbci::app
