// Whether to trust a run's data, from its summary: the calibration's AUC beside what chance and
// the simulated default subject give, the review's decision, the online accuracy (and post hoc),
// the timing verdict and the flashes off limits, the channels accepted at Start, the EEG's faults,
// losses and stalls, the interruptions and the notes. One list of rows, each flagged when it is a
// reason for caution, for the Summary panel and the session's report.html alike.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace arbci::session {

// The calibration's AUC as a new experimenter can judge it: its interval, the interval an AUC of
// these flashes lies in by chance (no response at all), and what the simulated default subject
// reaches. `targets` and `others`: the flashes it was measured on.
std::string aucReference(double auc, double low, double high, int targets, int others);

// The AUC of the simulated default subject's calibration run (8 selections of 8 sequences,
// cross-validated): lowest, median and highest of the default session's seeds 1-10
// (docs/session.md).
struct AucRange {
  double low, median, high;
};
inline constexpr AucRange kSimulatedSubjectAuc{0.64, 0.78, 0.93};

struct TrustRow {
  std::string what, text;
  bool caution = false;  // a reason to look again before using the data
};

// The rows for `summary` (summary.json); an empty list for a summary without a run.
std::vector<TrustRow> trustRows(const nlohmann::json& summary);

}  // namespace arbci::session
