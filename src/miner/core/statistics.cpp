#include "miner/core/statistics.hpp"

#include <cmath>
#include <stdexcept>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/special_functions/gamma.hpp>

namespace miner {

// Boost.Math (Debian's libboost-dev) instead of a hand-written series and continued fraction
// (issue 22: prefer a well-kept library to hand-written numerics). Arguments are checked here,
// with this project's messages, before Boost sees them.

double regularized_gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0) || !std::isfinite(a) || !std::isfinite(x))
    throw std::invalid_argument("regularized_gamma_p: needs finite a > 0, x >= 0");
  return boost::math::gamma_p(a, x);
}

double chi_square_cdf(double x, double k) {
  if (!(k > 0.0) || !std::isfinite(k)) throw std::invalid_argument("chi_square_cdf: needs finite k > 0");
  if (std::isnan(x)) throw std::invalid_argument("chi_square_cdf: x is NaN");
  if (x <= 0.0) return 0.0;
  if (std::isinf(x)) return 1.0;
  return boost::math::cdf(boost::math::chi_squared_distribution<double>(k), x);
}

double chi_square_quantile(double p, double k) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("chi_square_quantile: needs 0 < p < 1");
  if (!(k > 0.0) || !std::isfinite(k)) throw std::invalid_argument("chi_square_quantile: needs finite k > 0");
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(k), p);
}

}  // namespace miner
