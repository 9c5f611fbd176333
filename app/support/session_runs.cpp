#include "support/session_runs.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <nlohmann/json.hpp>

namespace arbci::app {

int nextFolderRun(const std::filesystem::path& session_folder, const core::RunLabels& labels) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::absolute(session_folder).lexically_normal();
  const fs::path parent =
      folder.has_filename() ? folder.parent_path() : folder.parent_path().parent_path();
  int highest = 0;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(parent, error)) {
    if (!entry.is_directory(error) || fs::equivalent(entry.path(), folder, error)) continue;
    std::ifstream in(entry.path() / "summary.json");
    if (!in) continue;
    const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    if (!summary.is_object() || !summary.contains("labels")) continue;
    const nlohmann::json& l = summary["labels"];
    if (!l.is_object() || l.value("subject", "") != labels.subject ||
        l.value("session", "") != labels.session || l.value("task", "") != labels.task)
      continue;
    const std::string run = l.value("run", "");
    if (run.empty() ||
        !std::all_of(run.begin(), run.end(), [](unsigned char c) { return std::isdigit(c); }))
      continue;
    highest = std::max(highest, std::stoi(run));
  }
  return highest + 1;
}

}  // namespace arbci::app
