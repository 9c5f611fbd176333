// Checks, before any work, that a file can be written where the user asked.
#pragma once

#include <filesystem>

namespace arbci::app {

// Throws CliError naming the path and the reason when `path` cannot be created or written.
// Creates missing parent folders only when `create_parents` is set.
void ensureWritable(const std::filesystem::path& path, bool create_parents = false);
// Creates `folder` (and its parents) if missing and checks a file can be written in it; throws
// CliError naming the folder and the reason.
void ensureWritableFolder(const std::filesystem::path& folder);

}  // namespace arbci::app
