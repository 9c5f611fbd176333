// Intervals and chance levels for classifier reports (what a reviewer asks of an AUC or an
// accuracy measured on a finite number of flashes and selections), and the median they share.
#pragma once

#include <vector>

namespace arbci::bci {

// The median of `values` (the upper one of an even count); 0 for none.
double median(std::vector<double> values);

struct Interval {
  double low = 0.0, high = 0.0;
};

// The 95 % interval of an AUC from `targets` and `others` scores (Hanley & McNeil 1982).
Interval aucInterval(double auc, int targets, int others);
// The 95 % Wilson score interval of `successes` out of `trials`.
Interval wilsonInterval(int successes, int trials);
// The smallest accuracy over `trials` selections that a guesser among `choices` reaches with a
// probability below 5 % (the one-sided binomial test's critical proportion).
double chanceLevel95(int choices, int trials);

// Decisions grouped by the certainty they claimed, against how many were wrong: a certainty
// means what it says when the wrong decisions of each band lie within what its claims allow.
struct ClaimedDecision {
  double certainty = 0.0;
  bool right = false;
};
struct ReliabilityBand {
  double low = 0.0, high = 0.0;  // certainties in [low, high)
  int decisions = 0, wrong = 0;
  double expected_wrong = 0.0;  // the sum of 1 - certainty
  // The central 95 % of the wrong count the claims allow: a sum of independent draws, each wrong
  // with its own 1 - certainty (Poisson-binomial, exact).
  int wrong_low = 0, wrong_high = 0;
  const char* verdict() const {
    return wrong > wrong_high ? "over-confident" : wrong < wrong_low ? "under-confident" : "within";
  }
};
// The bands [0, 0.9), [0.9, 0.99), [0.99, 0.999), [0.999, 1]; those with no decisions left out.
std::vector<ReliabilityBand> reliabilityBands(const std::vector<ClaimedDecision>& decisions);

}  // namespace arbci::bci
