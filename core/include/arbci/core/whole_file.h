// Writes a small file whole or not at all: to a temporary name beside it, flushed and checked,
// then renamed over the target. A full disk leaves the old file (or none), never a cut one.
#pragma once

#include <filesystem>
#include <string>

namespace arbci::core {

// "" when `text` is on disk as `path`; else why not, with the system's reason.
std::string writeWholeFile(const std::filesystem::path& path, const std::string& text);

}  // namespace arbci::core
