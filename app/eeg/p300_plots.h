// PNG plots for the training panel and for papers: the ERP averages (target against non-target)
// per channel, and accuracy and bit rate against the number of sequences.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"

namespace arbci::app {

// Writes erp.png and accuracy.png into `folder` (created if missing); returns their paths.
// Throws CliError when the folder cannot be written.
std::vector<std::filesystem::path> writeP300Plots(const std::filesystem::path& folder,
                                                  const bci::P300Dataset& data,
                                                  const bci::EvaluationReport& report,
                                                  const std::string& title);

}  // namespace arbci::app
