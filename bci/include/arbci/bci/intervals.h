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

}  // namespace arbci::bci
