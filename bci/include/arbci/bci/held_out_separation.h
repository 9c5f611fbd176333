// How sure a classifier learnt without labels may be. Its score model (bci::ScoreModel, the
// Gaussian model of target and non-target scores behind every certainty) comes from cross-
// validation against the labels the fit found; those labels were chosen by the same data, so on
// a weak response they agree with the scores more than the truth does, and the separation of the
// classes looks larger than it is. The certainty then runs ahead of the accuracy, and dynamic
// stopping and the arm act on it.
//
// What no fit has seen is honest: every selection a session decides is scored by a model fitted
// on the selections before it only. Those scores, each standardised by the score model of the
// model that scored it, are kept per selection; their separation is found without labels (EM over
// each selection's one attended choice, the class means weighted by its posterior, never by a
// hard choice), and a new fit's score model is allowed no larger separation than that. The models
// that scored them were fitted on fewer selections than the new one, so the bound errs towards
// less certainty; the session leaves out selections decided by models fitted on fewer selections
// than trust asks, which would hold every later model to their chance-level scores.
#pragma once

#include <optional>
#include <vector>

#include "arbci/bci/decision.h"
#include "arbci/bci/paradigm_layout.h"

namespace arbci::bci {

// Fewer decided selections than this bound nothing: the separation they show strays too far
// (downwards as much as upwards) to hold a model to it.
inline constexpr int kMinHeldOutSelections = 5;

// One selection's flashes as the session decided them: each flash's code and its score
// standardised by the model that scored it (bci::standardised).
struct HeldOutSelection {
  std::vector<int> code;
  std::vector<double> z;
};

// (score - midpoint of the class means) / sd: the units in which scores of different models are
// pooled.
double standardised(const ScoreModel& model, double score);

// The separation of the class means (target minus non-target, in pooled standard deviations) that
// the held-out selections show, each with exactly one attended choice (an object; a row and a
// column) that is not known. Every selection given counts: an estimate from fewer selections
// strays further, and it is its upward strays that would let the arm act on too little. None when
// no selection holds two codes of a group that flashed.
std::optional<double> heldOutSeparation(const std::vector<HeldOutSelection>& selections,
                                        const ParadigmLayout& layout);

// `fitted` with its class means drawn together about their midpoint until their separation is at
// most `separation` (in its standard deviations; the midpoint and the standard deviation kept,
// so scores standardise the same); at zero or below, both means at the midpoint: no evidence.
ScoreModel boundSeparation(const ScoreModel& fitted, double separation);

// A learnt fit's score model held to what the selections decided before it show: `model` bounded
// by heldOutSeparation(selections, layout) where there is one. Returns both separations, the
// fitted one (before the bound) and the held-out one (none before any selection), for the log.
struct SeparationBound {
  double fitted = 0.0;
  std::optional<double> held_out;
};
SeparationBound boundByHeldOut(ScoreModel& model, const std::vector<HeldOutSelection>& selections,
                               const ParadigmLayout& layout);

}  // namespace arbci::bci
