#pragma once
/// \file
/// C++ inference of the sGAN generator (paper Sec. IV-A.2, Alg. 1 line 2), exactly the graph
/// of src/python/sgan/model.py (c_k = maxpool_k([E/2, S])):
///     a1 = relu(conv3([E/2, S, N]))          w  x n^3
///     a2 = relu(conv3_s2(a1))                2w x (n/2)^3
///     a3 = relu(conv3_s2([a2, c2]))          4w x (n/4)^3
///     a4 = relu(conv3_s2([a3, c4]))          4w x (n/8)^3
///     m1 = relu(conv3([a4, c8, sigma]))      4w x (n/8)^3   (sigma: the scale input, below)
///     m2 = relu(conv3(m1))                   4w x (n/8)^3
///     d3 = relu(conv3([up2(m2), a3, c4]))    2w x (n/4)^3
///     d2 = relu(conv3([up2(d3), a2, c2]))    2w x (n/2)^3
///     R  = sigmoid(conv3([up2(d2), a1, E/2, S]))
/// The convolutions run in oneDNN (channels-last activations, weights reordered once to the
/// kernel's preferred layout), except enc1 and dec1's skip part at width 8 (sgan_kernels.hpp,
/// with 2 conditions or 5 for a network reading P);
/// a decoder layer's up-sampled input is convolved on its own coarse grid (parity kernels);
/// pooling and concatenation are copies done here.
/// Weights come from a `miner-tensors-v1` file of kind "sgan-weights" (tensor_file.hpp);
/// a missing, truncated, altered or mismatched file is refused naming the fault (REQ-HEUR-006).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/box.hpp"

namespace miner {
class Rng;
}

namespace miner::heuristic {

/// How step 1 of the filter thresholds R (REQ-HEUR-016): at the fixed threshold, or at the
/// smaller of it and the widest start-goal chain's bottleneck (region_filter.hpp).
enum class ThresholdRule { kFixed, kWidest };

struct SganArchitecture {
  int width = 8;
  /// 3 when the network is told its cells' metric size (issue 16 item 2): sigma, per axis
  /// log2(cell side / robot radius) / scale_divisor, constant channels beside the bottleneck's
  /// input; 0 for a network trained on one map family at one scale (no sigma).
  int scale_channels = 0;
  double scale_divisor = 4.0;
  Eigen::Vector3i dims = plan::HeuristicRegion::default_dims();  ///< nx, ny, nz; each divisible by 8
  double environment_scale = 0.5;   ///< E levels 0/1/2 enter the network as E * scale
  double threshold = 0.5;           ///< cell in the raw region iff R >= threshold
  /// "threshold_rule" in the file ("fixed" when absent, or "widest").
  ThresholdRule threshold_rule = ThresholdRule::kFixed;
  /// 3 when the network reads channel P (grid.hpp: whether each cell's free space joins its
  /// faces across x, y, z), as the blocked bits 1 - P_a, beside E and S in every condition c_k;
  /// 0 for the networks before it.
  int passability_channels = 0;
};

class Sgan {
 public:
  /// Which kernels run the two full-resolution layers (enc1 with its 3 or 6 input channels,
  /// dec1 with its one output channel): kFastest uses MINER's own (sgan_kernels.hpp: the sparse
  /// conditions E/2, S[, B] scattered, the dense ones gathered) for a width-8 network, oneDNN's
  /// otherwise; kOneDnn always oneDNN's (the tests compare the two).
  enum class Kernels { kFastest, kOneDnn };

  /// Loads and checks the weights file; builds the oneDNN primitives for one query.
  static Sgan load(const std::string& path);
  /// The same from the file's bytes (`origin` names them in messages).
  static Sgan from_bytes(const std::string& blob, const std::string& origin,
                         Kernels kernels = Kernels::kFastest);
  /// The weights shipped in fixtures/sgan/sgan.bin, compiled into the library (nothing is
  /// read or downloaded at run time).
  static Sgan builtin();
  /// load(path), or builtin() when path is empty (the CLI's and benchmarks' --weights).
  static Sgan load_or_builtin(const std::string& path);
  ~Sgan();
  Sgan(Sgan&&) noexcept;
  Sgan& operator=(Sgan&&) noexcept;

  const SganArchitecture& architecture() const;
  /// The file's "meta" object (architecture, training command, seeds, metrics).
  const Json& meta() const;
  const std::string& path() const;
  /// SHA-256 of the weights file's bytes (64 hex digits): what a campaign or a run folder records,
  /// since a path alone names whatever file is there later.
  const std::string& sha256() const;
  /// Whether MINER's own kernels run enc1 and dec1 (see Kernels).
  bool own_kernels() const;

  /// R = G(N | E, S[, B]) on the grid. Safe from several threads: the object's buffers are
  /// reused, so concurrent calls on one Sgan run one at a time (a mutex); for parallel
  /// inference give each thread its own Sgan. Inputs of dims.prod() floats each (x fastest): the environment already scaled,
  /// the state, the noise; dims.prod() probabilities out.
  /// `scale` is sigma (ignored, and may be empty, when the network has no scale channels);
  /// `passability` the network's P input, the blocked bits 1 - P_a for a = x, y, z as 0/1,
  /// channel after channel (3 x dims.prod(); ignored, and may be empty, when the network has no
  /// passability channels).
  std::vector<float> forward(const std::vector<float>& environment_scaled, const std::vector<float>& state,
                             const std::vector<float>& noise, const std::vector<float>& scale = {},
                             const std::vector<float>& passability = {}) const;

  /// The same from the dataset encoding (E levels 0/1/2, S 0/1, P bits; grid.hpp) of a grid over
  /// `bounds` for a robot of `robot_radius` (which give sigma), with N(0, 1) noise drawn from
  /// `rng`. `passability` may be empty when the network has no passability channels.
  std::vector<float> predict(const std::vector<std::uint8_t>& environment, const std::vector<std::uint8_t>& state,
                             const std::vector<std::uint8_t>& passability, const world::Box& bounds,
                             double robot_radius, Rng& rng) const;

 private:
  struct Impl;
  explicit Sgan(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  /// *impl_, or miner::Error when the network was moved from.
  Impl& live() const;
};

/// |sigma| is clamped here: the shipped network saw sigma in [-0.27, 1.14] (cells of 1/2 to 23
/// radii); beyond 2 (cells of 256 radii at divisor 4) it would extrapolate further still, and
/// a point robot (radius 0) has sigma = +2 instead of infinity.
inline constexpr double kScaleLimit = 2.0;

/// sigma for a grid of `dims` cells over `bounds` and a robot of `robot_radius`:
/// sigma_a = clamp(log2(cell_a / robot_radius) / divisor, +-kScaleLimit), cell_a =
/// (bounds.max_a - bounds.min_a) / dims_a (model.py's scale_input, the same doubles). Throws
/// miner::Error unless every cell side is positive and finite and the radius finite and >= 0.
std::vector<float> scale_input(const world::Box& bounds, const Eigen::Vector3i& dims, double robot_radius,
                               double divisor);

/// Agreement with PyTorch: float32 convolutions summed in another order differ by a few ulps
/// per layer; the bound on the probabilities.
inline constexpr double kReferenceTolerance = 1e-4;

/// Runs every sample of a "sgan-reference" file (inputs and PyTorch's output, written by
/// train.py) through `sgan`; returns max |C++ - PyTorch| per sample. Throws miner::Error
/// naming the file if its tensors do not fit the weights' grid.
std::vector<double> reference_errors(const Sgan& sgan, const std::string& reference_path);

}  // namespace miner::heuristic
