// Plots for papers: the ERPs per channel (target and non-target averages with their standard-error
// bands and the difference wave; the numbers in erp.json), and accuracy and bit rate against the
// number of sequences.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"

namespace arbci::app {

// What the two classes are called in the figures (an ErrP classifier's are error and correct).
struct ClassNames {
  std::string target = "target", other = "non-target";
};

// Writes erp.png, erp.json (the figure's numbers) and accuracy.png into `folder` (created if
// missing); returns their paths.
// Throws CliError when the folder cannot be written.
std::vector<std::filesystem::path> writeP300Plots(const std::filesystem::path& folder,
                                                  const bci::P300Dataset& data,
                                                  const bci::EvaluationReport& report,
                                                  const std::string& title,
                                                  const ClassNames& names = {},
                                                  const bci::ScalpTime& when = {});

// What the averages (and the classifier's epochs) went through, in a line ("filter: 4th-order
// Butterworth 0.5-20 Hz band-pass, 50 Hz notch (Q 25), zero-phase; reference: as recorded; left
// out: Fz (flat)") and as data (reference, filter, baseline, epoch and window, the channels left
// out and why, the selections and epochs): every figure, erp.json and the report carry them.
std::string analysisText(const bci::ErpCurves& erp);
nlohmann::json analysisJson(const bci::ErpCurves& erp);

// erp.json: per channel the time axis (ms), the target and non-target averages, their difference
// and standard errors (uV), with what was done: the reference, the filter (type, order, band,
// notch and its Q, zero-phase or causal), the epoch, baseline and analysis window, the channels
// left out and why, the selections and epochs behind it, and the scalp map's time.
nlohmann::json erpJson(const bci::ErpCurves& erp, const bci::ScalpTime& when = {});

}  // namespace arbci::app
