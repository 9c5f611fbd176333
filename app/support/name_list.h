// Splits comma-separated names as given on the command line ("Fz,Cz,Pz"), dropping empty ones.
#pragma once

#include <string>
#include <vector>

namespace arbci::app {

std::vector<std::string> splitNameList(const std::string& text);

}  // namespace arbci::app
