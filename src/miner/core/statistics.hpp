#pragma once
/// \file
/// Chi-square distribution (REQ-CORE-005): the EKF's innovation gate and the NEES/NIS
/// consistency tests both need its quantiles for arbitrary degrees of freedom.
///
/// F(x; k) = P(k/2, x/2), the regularised lower incomplete gamma function; both, and the
/// quantiles, from Boost.Math (Debian's libboost-dev), with this project's argument checks.

namespace miner {

/// Regularised lower incomplete gamma P(a, x), a > 0, x >= 0.
double regularized_gamma_p(double a, double x);

/// P(X <= x) for X ~ chi2(k), k > 0.
double chi_square_cdf(double x, double k);

/// The x with chi_square_cdf(x, k) = p, p in (0, 1), to double precision.
double chi_square_quantile(double p, double k);

}  // namespace miner
