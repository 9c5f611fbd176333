// The --session option of the commands that run a session: the embedded default when empty,
// else that file over the defaults; a bad file is a CliError naming the key.
#pragma once

#include <string>

#include "arbci/session/session_config.h"

namespace arbci::app {

session::SessionConfig loadSessionOption(const std::string& path);

}  // namespace arbci::app
