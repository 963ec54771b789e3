#pragma once
/// \file
/// MINER's own kernels for the sGAN generator's two full-resolution layers at width 8 (the
/// shipped network), where oneDNN's are least efficient (3 or 6 input channels into enc1; one
/// output channel out of dec1). Both read zero-padded grids, so every voxel takes the same
/// path (zero padding is the convolutions' padding 1), and both skip the work that the
/// conditions (E/2, S and, for a network reading P, the blocked bits) make zero: they are
/// constant over most of the grid and zero on 70-80 % of it, so their taps are scattered from
/// the nonzero voxels only, while the
/// dense channels (the noise N into enc1, a1 into dec1) are gathered. Compiled for
/// x86-64-v4 (AVX-512), x86-64-v3 (AVX2 + FMA) and the baseline, picked at load time by the
/// CPU (GCC target_clones): bytes are the same for the same machine, as oneDNN's are.
///
/// Grids: n = (nx, ny, nz) voxels, x fastest; a padded grid has (nx + 2)(ny + 2)(nz + 2)
/// voxels, voxel (x, y, z) of the grid at padded (x + 1, y + 1, z + 1), the border zero.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace miner::heuristic::kernels {

/// The width of the network the kernels are for (a1 has 8 channels).
inline constexpr int kWidth = 8;

/// Most condition channels c = (E/2, S[, B_x, B_y, B_z]) the kernels take: 2, or 5 for a network
/// reading channel P as its blocked bits (sgan.hpp), which are zero on free cells like E and S.
inline constexpr int kMaxConditions = 5;

/// A nonzero voxel of the sparse inputs: its index in the padded grid and its conditions (the
/// first `conditions` used).
struct SparseInput {
  std::int32_t padded;
  float condition[kMaxConditions];
};

/// a1 = relu(conv3([c, N]) + bias), written channels-last into the interior of the padded
/// a1_padded ((nx + 2)(ny + 2)(nz + 2) x 8 floats; the border is left zero: the sparse taps are
/// scattered without bounds tests, onto the border too, which is cleared afterwards).
///   conditions: the number of condition channels c (2 or kMaxConditions);
///   noise_padded: N on the padded grid (planar, border zero);
///   sparse: the voxels where a condition is nonzero;
///   weights: PyTorch's oidhw [8][conditions + 1][27] (input channels c, then N); bias[8].
void first_layer(const int n[3], int conditions, const float* noise_padded, const std::vector<SparseInput>& sparse,
                 const float* weights, const float* bias, float* a1_padded);

/// The logits' skip part of dec1 added to `logits` (nx ny nz floats, holding the bias and the
/// up-sampled part): logits[v] += sum over taps t of a1[v + t] . W_a[t] + sum_k c_k[v + t] W_k[t],
/// with a1 from first_layer (padded, channels-last), each condition c_k on the padded grid
/// (planar; one output channel, so they are gathered 8 voxels to a vector, cheaper than a
/// scatter here) and skip_weights PyTorch's [1][8 + conditions][27] (input channels a1 0..7, then c).
void last_layer_skip(const int n[3], int conditions, const float* a1_padded, const float* const* condition_padded,
                     const float* skip_weights, float* logits);

}  // namespace miner::heuristic::kernels
