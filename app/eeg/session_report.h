// A session folder's report, readable without ARBCI: report.html beside summary.json, with
// whether to trust the data (session/trust_report.h), each trial's selections, and the figures of
// the calibration run made again from the folder's own files (recording.bdf, model.json): the ERP
// per channel and the cross-validated accuracy by sequences (report/erp.png, report/accuracy.png,
// report/erp.json). Written when a run ends, headless or in the window.
#pragma once

#include <filesystem>
#include <string>

namespace arbci::app {

// Writes FOLDER/report.html (and FOLDER/report/); returns its path, or throws std::runtime_error
// with the reason when the folder holds no summary. Figures that cannot be made (no model, no
// calibration run) are left out with the reason written in their place.
std::filesystem::path writeSessionReport(const std::filesystem::path& folder);

}  // namespace arbci::app
