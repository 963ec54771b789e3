#include "miner/core/rng.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace miner {

namespace {
__extension__ typedef unsigned __int128 Uint128;  // GCC/Clang extension, exact 64x64 product

constexpr double kTwoPowMinus53 = 1.0 / 9007199254740992.0;  // 2^-53

/// The ziggurat's layers for f(x) = exp(-x^2/2) (Marsaglia & Tsang 2000, Sec. 2): layer i >= 1
/// is the rectangle [0, x_i] x [f(x_i), f(x_{i+1})], layer 0 the base [0, x_0] x [0, f(r)]
/// with x_0 = v / f(r), which also stands for the tail beyond r. Every layer has area v:
/// x_i (f(x_{i+1}) - f(x_i)) = v gives x_{i+1} = sqrt(-2 ln(v / x_i + f(x_i))), and r, v are
/// the published 256-layer constants that close the top layer (x_256 = 0; checked in the tests
/// to 1e-9 relative through ziggurat_top_layer_area()).
struct Ziggurat {
  static constexpr int kLayers = 256;
  static constexpr double kR = 3.6541528853610088;
  static constexpr double kV = 0.00492867323399;
  std::array<double, kLayers + 1> x{};
  std::array<double, kLayers + 1> fx{};    // f(x_i)
  std::array<double, kLayers> inner{};     // x_{i+1} / x_i: |u| below it is under the curve

  static double f(double t) { return std::exp(-0.5 * t * t); }

  Ziggurat() {
    x[0] = kV / f(kR);
    x[1] = kR;
    for (int i = 1; i + 1 < kLayers; ++i)
      x[static_cast<std::size_t>(i + 1)] = std::sqrt(-2.0 * std::log(kV / x[static_cast<std::size_t>(i)] +
                                                                      f(x[static_cast<std::size_t>(i)])));
    x[kLayers] = 0.0;
    for (std::size_t i = 0; i <= kLayers; ++i) fx[i] = f(x[i]);
    for (std::size_t i = 0; i < kLayers; ++i) inner[i] = x[i + 1] / x[i];
  }
};

const Ziggurat& ziggurat() {
  static const Ziggurat z;
  return z;
}
}  // namespace

double ziggurat_top_layer_area() {
  const Ziggurat& z = ziggurat();
  return z.x[Ziggurat::kLayers - 1] * (1.0 - z.fx[Ziggurat::kLayers - 1]) / Ziggurat::kV;
}

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

Rng::Rng(std::uint64_t seed, std::uint64_t stream) : engine_(splitmix64(seed ^ stream)) {}

double Rng::uniform01() {
  return static_cast<double>(engine_() >> 11) * kTwoPowMinus53;
}

double Rng::uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }

std::uint64_t Rng::uniform_index(std::uint64_t n) {
  if (n == 0) throw std::invalid_argument("Rng::uniform_index: n must be at least 1");
  // Lemire, "Fast random integer generation in an interval", ACM TOMACS 2019.
  Uint128 m = static_cast<Uint128>(engine_()) * n;
  auto low = static_cast<std::uint64_t>(m);
  if (low < n) {
    const std::uint64_t threshold = (0 - n) % n;
    while (low < threshold) {
      m = static_cast<Uint128>(engine_()) * n;
      low = static_cast<std::uint64_t>(m);
    }
  }
  return static_cast<std::uint64_t>(m >> 64);
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u = 0.0, v = 0.0, s = 0.0;
  do {
    u = 2.0 * uniform01() - 1.0;
    v = 2.0 * uniform01() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

double Rng::normal_ziggurat() { return ziggurat_from(engine_()); }

double Rng::ziggurat_from(std::uint64_t bits) {
  const Ziggurat& z = ziggurat();
  for (;;) {
    const std::size_t i = bits & (Ziggurat::kLayers - 1);
    const double u = 2.0 * static_cast<double>(bits >> 11) * kTwoPowMinus53 - 1.0;  // [-1, 1)
    if (std::fabs(u) < z.inner[i]) return u * z.x[i];  // inside the layer's core rectangle
    if (i == 0) {
      // Tail |x| > r: a = -ln(U1) / r, b = -ln(U2), accepted when 2b >= a^2 (Marsaglia 1964).
      double a = 0.0, b = 0.0;
      do {
        a = -std::log(1.0 - uniform01()) / Ziggurat::kR;
        b = -std::log(1.0 - uniform01());
      } while (b + b < a * a);
      return u < 0.0 ? -(Ziggurat::kR + a) : Ziggurat::kR + a;
    }
    // The wedge between x_{i+1} and x_i: a uniform height in the layer, kept under f.
    const double t = u * z.x[i];
    if (z.fx[i] + uniform01() * (z.fx[i + 1] - z.fx[i]) < Ziggurat::f(t)) return t;
    bits = engine_();
  }
}

void Rng::fill_normal_ziggurat(float* out, std::size_t n) {
  const Ziggurat& z = ziggurat();
  // SplitMix64's own sequence from a key drawn from this stream: value i is splitmix64(key +
  // i gamma), gamma its golden-ratio increment (splitmix64 adds one more before mixing).
  constexpr std::uint64_t kGamma = 0x9E3779B97F4A7C15ULL;
  std::uint64_t counter = engine_();
  for (std::size_t k = 0; k < n; ++k, counter += kGamma) {
    const std::uint64_t bits = splitmix64(counter);
    const std::size_t i = bits & (Ziggurat::kLayers - 1);
    const double u = 2.0 * static_cast<double>(bits >> 11) * kTwoPowMinus53 - 1.0;
    // The core rectangle as in ziggurat_from; the rest (1.5 %) finishes there, on the engine.
    out[k] = static_cast<float>(std::fabs(u) < z.inner[i] ? u * z.x[i] : ziggurat_from(bits));
  }
}

}  // namespace miner
