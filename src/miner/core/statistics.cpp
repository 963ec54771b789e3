#include "miner/core/statistics.hpp"

#include <cmath>
#include <stdexcept>

namespace miner {

namespace {
/// Series and continued fraction stop when a term changes the sum by less than this
/// (relative); double precision cannot resolve more.
constexpr double kConvergence = 1e-16;
constexpr int kMaxTerms = 10000;
/// Lentz's guard against a zero denominator.
constexpr double kTiny = 1e-300;
}  // namespace

double regularized_gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw std::invalid_argument("regularized_gamma_p: needs a > 0, x >= 0");
  if (x == 0.0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    // P = x^a e^-x / Gamma(a+1) * sum_n x^n / ((a+1)...(a+n))
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < kMaxTerms; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * kConvergence) break;
    }
    return std::exp(log_prefactor) * sum;
  }
  // Q = x^a e^-x / Gamma(a) * 1/(x+1-a- 1(1-a)/(x+3-a- 2(2-a)/(x+5-a- ...)))
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int n = 1; n < kMaxTerms; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kConvergence) break;
  }
  return 1.0 - std::exp(log_prefactor) * h;
}

double chi_square_cdf(double x, double k) {
  if (!(k > 0.0)) throw std::invalid_argument("chi_square_cdf: needs k > 0");
  return x <= 0.0 ? 0.0 : regularized_gamma_p(0.5 * k, 0.5 * x);
}

double chi_square_quantile(double p, double k) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("chi_square_quantile: needs 0 < p < 1");
  double lo = 0.0, hi = k + 10.0 * std::sqrt(2.0 * k) + 10.0;
  while (chi_square_cdf(hi, k) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi_square_cdf(mid, k) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace miner
