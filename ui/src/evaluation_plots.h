// A classifier's cross-validated quality as the Training panel shows it, for a model trained in
// the panel and for the session's own: AUC with its interval, the selections and chance, and
// accuracy and bit rate by sequences on plots with their scales, the chance and p < 0.05 lines.
#pragma once

#include "arbci/bci/evaluation.h"

namespace arbci::ui {

void drawEvaluation(const bci::EvaluationReport& report);

}  // namespace arbci::ui
