// An evaluation report, printed and as data: the single-flash AUC with its 95 % interval; where
// the codes are choices, selections, accuracy (with 95 % intervals and the chance level),
// selection time and bit rate by number of sequences (flash time only, and as recorded), and
// dynamic stopping. And the scores, one row per flash.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "arbci/bci/evaluation.h"

namespace arbci::app {

// How the two classes are named: a P300 report's "target and non-target flashes", an ErrP
// report's "error and correct feedbacks".
struct ReportWords {
  std::string target = "target", other = "non-target", events = "flashes";
  std::string event = "flash";  // "single-flash AUC"
  bool paradigm = true;         // the events are a paradigm's stimuli (feedbacks are not)
  static ReportWords errp() { return {"error", "correct", "feedbacks", "feedback", false}; }
};

void printReport(std::ostream& out, const bci::EvaluationReport& report,
                 const ReportWords& words = {});
// Everything printReport prints, as JSON.
nlohmann::json reportJson(const bci::EvaluationReport& report);
// One row per flash: file, sample, code, label (1 target, 0 non-target), score, fold (-1: none).
// Throws CliError when the file cannot be written.
void writeScoresCsv(const std::filesystem::path& path, const bci::P300Dataset& data,
                    const std::vector<double>& scores, const std::vector<int>& fold);
// A progress line on stderr that rewrites itself.
bci::Progress progressLine(std::ostream& err);

}  // namespace arbci::app
