// Files the executable tests make and read: a fresh (removed) temporary path, a scratch folder's
// path, and JSON files.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace arbci::test {

// <temp>/arbci_<suite>_<process id>_<name>, removed if it exists (a folder or file the test then
// makes); the process id keeps tests run in parallel apart.
std::filesystem::path freshTempPath(const std::string& suite, const std::string& name);
// <temp>/<folder>/<name>, the folder made if missing; the path itself is left as it is, so a test
// may write it and read it back.
std::filesystem::path scratchPath(const std::string& folder, const std::string& name);
// A file's bytes ("" when it cannot be read).
std::string fileBytes(const std::filesystem::path& path);
// Throws (through nlohmann::json) when the file is missing or not JSON.
nlohmann::json readJson(const std::filesystem::path& path);

}  // namespace arbci::test
