// Distribution functions and quantiles the host's tests and intervals need: normal, Student's t,
// chi-square and F. Computed from the regularized incomplete gamma and beta functions (series and
// Lentz continued fractions, as in the standard references: Abramowitz & Stegun 6.5 and 26.5), and
// quantiles by bracketing and bisection on the distribution function to full precision. Exact
// to double precision where a table or an approximation formula would not be: a false-alarm rate
// stated to users rests on these.
#pragma once

namespace vibid::numerics {

/// P(a, x) = γ(a, x)/Γ(a), a > 0, x ≥ 0.
double RegularizedGammaP(double a, double x);
/// I_x(a, b), a, b > 0, 0 ≤ x ≤ 1.
double RegularizedBeta(double a, double b, double x);

double NormalCdf(double x);
double StudentTCdf(double t, double dof);
double ChiSquareCdf(double x, double dof);
double FCdf(double x, double dof1, double dof2);

/// Quantiles: the value q with CDF(q) = p, 0 < p < 1; InputError for p or a dof out of range.
double NormalQuantile(double p);
double StudentTQuantile(double p, double dof);
double ChiSquareQuantile(double p, double dof);
double FQuantile(double p, double dof1, double dof2);

}  // namespace vibid::numerics
