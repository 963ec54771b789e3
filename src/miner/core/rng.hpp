#pragma once
/// \file
/// The project's only source of randomness (REQ-CORE-001).
///
/// A std::mt19937_64 engine whose seed is derived per stream with SplitMix64, and
/// uniform / normal transforms written here, because the standard distributions
/// (std::uniform_real_distribution, std::normal_distribution) are allowed to differ
/// between standard libraries. The same seed gives the same numbers everywhere.

#include <cstddef>
#include <cstdint>
#include <random>

namespace miner {

/// SplitMix64 (Steele, Lea, Flood 2014): a bijective 64-bit mixer, used to turn
/// (master seed, stream) into well-spread engine seeds.
std::uint64_t splitmix64(std::uint64_t x);

/// The stream of retry `attempt` of a seeded draw (a generator that redraws until its map is
/// solvable): 0 for the first try, SplitMix64(attempt) after it. Rng(seed, attempt) would make
/// retry a of seed s the first try of seed s ^ a, so two small user seeds would give the same
/// map whenever one of them needed a retry; the mixed stream keeps every (seed, attempt) apart.
inline std::uint64_t retry_stream(std::uint64_t attempt) { return attempt == 0 ? 0 : splitmix64(attempt); }

/// Area of Rng::normal_ziggurat()'s top layer over the common layer area v: 1 when the
/// published (r, v) close the ziggurat with the recurrence computed here (a test checks it).
double ziggurat_top_layer_area();

/// Seeded random number generator.
/// The project's named random streams (issue 22: their numbers were literals in six files).
/// A draw is Rng(seed, stream); keeping every use of a seed on its own stream keeps the uses
/// independent and each one reproducible alone. Indexed families (a campaign's run r, a
/// generator's retry a, a scan's pose k) use their index as the stream, offset where noted.
namespace streams {
inline constexpr std::uint64_t kImuNoise = 1;          ///< flight: IMU noise and bias walks
inline constexpr std::uint64_t kPoseNoise = 2;         ///< flight: pose noise and outliers
inline constexpr std::uint64_t kInitialEstimate = 3;   ///< flight: the EKF's initial error
inline constexpr std::uint64_t kWind = 4;              ///< flight: Dryden turbulence
inline constexpr std::uint64_t kPoseVio = 5;           ///< flight: VIO drift, tracking losses, delay jitter
inline constexpr std::uint64_t kSganNoise = 0x5347414e;  ///< heuristic: the generator's noise ("SGAN")
/// heuristic: a dataset sample's query, on its map seed (a stream the map generator never uses)
inline constexpr std::uint64_t kDatasetQuery = 0x9e3779b97f4a7c15ULL;
/// bench: OMPL's run r draws from kOmplRunBase + r (above every run index of our planners)
inline constexpr std::uint64_t kOmplRunBase = std::uint64_t{1} << 40;
}  // namespace streams

class Rng {
 public:
  /// Stream `stream` of master seed `seed`: engine seeded with SplitMix64(seed ^ stream),
  /// so trial k of a Monte Carlo campaign is Rng(seed, k) whatever ran before it.
  explicit Rng(std::uint64_t seed, std::uint64_t stream = 0);

  /// Raw 64-bit output of the engine.
  std::uint64_t next_u64() { return engine_(); }

  /// Uniform on [0, 1): the top 53 bits of one draw times 2^-53 (exact, no rounding).
  double uniform01();

  /// Uniform on [lo, hi): lo + (hi - lo) * uniform01().
  double uniform(double lo, double hi);

  /// Uniform integer on [0, n), n >= 1, unbiased (Lemire 2019, multiply + reject).
  std::uint64_t uniform_index(std::uint64_t n);

  /// Standard normal N(0, 1) by Marsaglia's polar method (uses only log and sqrt);
  /// the second variate of each pair is cached.
  double normal();

  /// N(mean, stddev^2).
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

  /// Standard normal N(0, 1) by the ziggurat method (Marsaglia & Tsang 2000, 256 layers of
  /// equal area v under f(x) = exp(-x^2/2), tail beyond r = 3.6541528853610088 by Marsaglia's
  /// 1964 exponential rejection). One draw gives the layer (its low 8 bits) and the signed
  /// uniform (its top 53 bits, disjoint from the layer's, Doornik 2005); 98.5 % of the draws
  /// end after one compare and one multiply, ~5x faster than normal(). A different sequence
  /// than normal() for the same seed.
  double normal_ziggurat();

  /// out[0..n) <- N(0, 1) by the same ziggurat, its first draws taken from SplitMix64's own
  /// sequence (Steele, Lea, Flood 2014: splitmix64(key + k gamma), a generator of its own that
  /// passes BigCrush) keyed by one draw of this stream; the 1.5 % outside a layer's core
  /// rectangle finish on this stream's engine. ~3x faster than n calls of normal_ziggurat()
  /// (the Mersenne Twister's refills were a tenth of the sGAN's query, issue 16); the sGAN's
  /// 32^3 noise grid per query uses it. Same seed, same numbers.
  void fill_normal_ziggurat(float* out, std::size_t n);

 private:
  /// normal_ziggurat() from its first draw `bits` (further draws from the engine).
  double ziggurat_from(std::uint64_t bits);

  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace miner
