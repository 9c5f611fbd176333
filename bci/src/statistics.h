// Distribution functions the stepwise regression needs (no Debian library we use has them).
#pragma once

namespace arbci::bci {

// The regularized incomplete beta function I_x(a, b), by Lentz's continued fraction.
double incompleteBeta(double a, double b, double x);
// Two-sided p-value of a Student t statistic with `df` degrees of freedom.
double studentTwoSidedP(double t, double df);

}  // namespace arbci::bci
