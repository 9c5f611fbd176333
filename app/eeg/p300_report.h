// Prints an evaluation report: selections, accuracy, selection time and bit rate by number of
// sequences, and dynamic stopping.
#pragma once

#include <ostream>

#include "arbci/bci/evaluation.h"

namespace arbci::app {

void printReport(std::ostream& out, const bci::EvaluationReport& report);
// A progress line on stderr that rewrites itself.
bci::Progress progressLine(std::ostream& err);

}  // namespace arbci::app
