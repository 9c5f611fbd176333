// Runs numbered without a BIDS dataset: the session folders beside one another (the --out
// folders of one study, or the time-stamped ones in the working folder) are its runs, each
// folder's summary.json saying whose run it was.
#pragma once

#include <filesystem>

#include "arbci/core/run_labels.h"

namespace arbci::app {

// The next run for `labels`' subject, session and task: one more than the highest run recorded
// with the same three in the summary.json of the folders beside `session_folder` (1 when none).
int nextFolderRun(const std::filesystem::path& session_folder, const core::RunLabels& labels);

}  // namespace arbci::app
