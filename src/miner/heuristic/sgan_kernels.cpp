#include "miner/heuristic/sgan_kernels.hpp"

#include <algorithm>
#include <cstring>

namespace miner::heuristic::kernels {

namespace {

// Eight floats (one voxel's 8 channels, or 8 voxels' sums): GCC's vector extension, lowered to
// one AVX register in the x86-64-v3/v4 clones and to two SSE registers in the baseline one.
// Never passed by value between functions (the baseline ABI has no 32-byte registers).
using v8 = float __attribute__((vector_size(32)));
using v8i = int __attribute__((vector_size(32)));

// Lanes i0..i7 of the 16 of (a, b): GCC's and Clang's spellings (ci/fuzz.sh builds with Clang).
#if defined(__clang__)
#define MINER_SHUFFLE8(a, b, i0, i1, i2, i3, i4, i5, i6, i7) __builtin_shufflevector(a, b, i0, i1, i2, i3, i4, i5, i6, i7)
#define MINER_KERNEL_CLONES
#else
#define MINER_SHUFFLE8(a, b, i0, i1, i2, i3, i4, i5, i6, i7) __builtin_shuffle(a, b, v8i{i0, i1, i2, i3, i4, i5, i6, i7})
#define MINER_KERNEL_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif

/// r <- p[0..7] (unaligned); by reference, as no v8 crosses a function boundary by value.
inline void load8(v8& r, const float* p) { std::memcpy(&r, p, sizeof r); }

/// Zeroes the border of a padded grid of c floats per voxel (its six faces).
void clear_border(const int n[3], int c, float* padded) {
  const std::ptrdiff_t px = n[0] + 2, py = n[1] + 2, pz = n[2] + 2;
  for (std::ptrdiff_t z = 0; z < pz; ++z)
    for (std::ptrdiff_t y = 0; y < py; ++y) {
      float* row = padded + (z * py + y) * px * c;
      if (z == 0 || z == pz - 1 || y == 0 || y == py - 1) {
        std::fill(row, row + px * c, 0.0f);
      } else {
        std::fill(row, row + c, 0.0f);
        std::fill(row + (px - 1) * c, row + px * c, 0.0f);
      }
    }
}

/// first_layer's sparse part for NC conditions (a compile-time count: the channel loop unrolls).
template <int NC>
[[gnu::always_inline]] inline void scatter_conditions(const std::vector<SparseInput>& sparse,
                                                      const v8 (&wc)[kMaxConditions][27], const std::ptrdiff_t (&off)[27],
                                                      float* a1_padded) {
  for (const SparseInput& s : sparse) {
    float c[NC];
    for (int k = 0; k < NC; ++k) c[k] = s.condition[k];
    for (int t = 0; t < 27; ++t) {
      float* dst = a1_padded + (s.padded - off[t]) * kWidth;
      v8 cur;
      load8(cur, dst);
      v8 add = c[0] * wc[0][t] + c[1] * wc[1][t];
      for (int k = 2; k < NC; ++k) add += c[k] * wc[k][t];
      cur += add;
      std::memcpy(dst, &cur, sizeof cur);
    }
  }
}

/// last_layer_skip's conditions for the 8 voxels from `at` (padded index) on: sum over taps t and
/// conditions k of c_k[at + tap_t] W_k[t], E/2 and S as one expression (the bytes before P).
template <int NC>
[[gnu::always_inline]] inline void gather_conditions(v8& sum, const float* const* condition_padded, std::ptrdiff_t at,
                                                     const std::ptrdiff_t (&tap)[27],
                                                     const float (&wc)[kMaxConditions][27]) {
  const float* planes[NC];
  for (int k = 0; k < NC; ++k) planes[k] = condition_padded[k] + at;
  for (int t = 0; t < 27; ++t) {
    v8 e, st;
    load8(e, planes[0] + tap[t]);
    load8(st, planes[1] + tap[t]);
    v8 add = e * wc[0][t] + st * wc[1][t];
    for (int k = 2; k < NC; ++k) {
      v8 b;
      load8(b, planes[k] + tap[t]);
      add += b * wc[k][t];
    }
    sum += add;
  }
}

}  // namespace

// Tap t = (dz + 1) 9 + (dy + 1) 3 + (dx + 1), as PyTorch's [kd][kh][kw] flattened. A voxel v
// reads input v + (dx, dy, dz) at tap t, so an input u reaches the outputs u - (dx, dy, dz).

MINER_KERNEL_CLONES
void first_layer(const int n[3], int conditions, const float* noise_padded, const std::vector<SparseInput>& sparse,
                 const float* weights, const float* bias, float* a1_padded) {
  const int nx = n[0], ny = n[1], nz = n[2];
  const std::ptrdiff_t px = nx + 2, pxy = px * (ny + 2);
  std::fill(a1_padded, a1_padded + pxy * (nz + 2) * kWidth, 0.0f);
  const int nc = std::clamp(conditions, 2, kMaxConditions), cin = nc + 1;
  v8 wn[27], wc[kMaxConditions][27];
  for (int t = 0; t < 27; ++t)
    for (int o = 0; o < kWidth; ++o) {
      for (int c = 0; c < nc; ++c) wc[c][t][o] = weights[(o * cin + c) * 27 + t];
      wn[t][o] = weights[(o * cin + nc) * 27 + t];
    }
  // The conditions, scattered from their nonzero voxels to the 27 voxels that read each, border
  // voxels included (cleared below). E/2 and S first, summed as one expression as before the
  // blocked bits came, so a 2-condition network gives the same bytes.
  std::ptrdiff_t off[27];
  for (int t = 0; t < 27; ++t) off[t] = (t / 9 - 1) * pxy + (t / 3 % 3 - 1) * px + (t % 3 - 1);
  if (nc == 2)
    scatter_conditions<2>(sparse, wc, off, a1_padded);
  else
    scatter_conditions<kMaxConditions>(sparse, wc, off, a1_padded);
  clear_border(n, kWidth, a1_padded);
  // N gathered for 8 voxels along x at a time (independent sums), the bias, ReLU.
  v8 b;
  load8(b, bias);
  const v8 zero = {};
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const std::ptrdiff_t row = (z + 1) * pxy + (y + 1) * px + 1;  // padded index of (0, y, z)
      const float* nrow = noise_padded + row;
      float* arow = a1_padded + row * kWidth;
      for (int x = 0; x + 8 <= nx; x += 8) {
        v8 acc[8];
        for (int j = 0; j < 8; ++j) {
          load8(acc[j], arow + (x + j) * kWidth);
          acc[j] += b;
        }
        for (int t = 0; t < 27; ++t) {
          const v8 w = wn[t];
          const float* p = nrow + x + off[t];
          for (int j = 0; j < 8; ++j) acc[j] += p[j] * w;
        }
        for (int j = 0; j < 8; ++j) {
          const v8 r = (v8)((v8i)acc[j] & (acc[j] > zero));  // ReLU: the lanes above zero, else +0
          std::memcpy(arow + (x + j) * kWidth, &r, sizeof r);
        }
      }
    }
}

MINER_KERNEL_CLONES
void last_layer_skip(const int n[3], int conditions, const float* a1_padded, const float* const* condition_padded,
                     const float* skip_weights, float* logits) {
  const int nx = n[0], ny = n[1], nz = n[2];
  const std::ptrdiff_t px = nx + 2, pxy = px * (ny + 2);
  const int nc = std::clamp(conditions, 2, kMaxConditions);
  v8 wa[27];
  float wc[kMaxConditions][27];
  for (int t = 0; t < 27; ++t) {
    for (int c = 0; c < kWidth; ++c) wa[t][c] = skip_weights[c * 27 + t];
    for (int c = 0; c < nc; ++c) wc[c][t] = skip_weights[(kWidth + c) * 27 + t];
  }
  std::ptrdiff_t tap[27];
  for (int t = 0; t < 27; ++t) tap[t] = (t / 9 - 1) * pxy + (t / 3 % 3 - 1) * px + (t % 3 - 1);
  std::ptrdiff_t off[27];
  for (int t = 0; t < 27; ++t) off[t] = ((t / 9 - 1) * pxy + (t / 3 % 3 - 1) * px + (t % 3 - 1)) * kWidth;
  // Pairwise sums of 8 accumulators into one vector of 8 totals (an 8 x 8 transpose-add).
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const std::ptrdiff_t row = (z + 1) * pxy + (y + 1) * px + 1;  // padded index of (0, y, z)
      const float* arow = a1_padded + row * kWidth;
      float* out = logits + (static_cast<std::ptrdiff_t>(z) * ny + y) * nx;
      for (int x = 0; x + 8 <= nx; x += 8) {
        v8 acc[8] = {};
        v8 sparse_part = {};  // the conditions: the 8 voxels in the lanes
        if (nc == 2)
          gather_conditions<2>(sparse_part, condition_padded, row + x, tap, wc);
        else
          gather_conditions<kMaxConditions>(sparse_part, condition_padded, row + x, tap, wc);
        for (int t = 0; t < 27; ++t) {
          const v8 w = wa[t];
          const float* p = arow + x * kWidth + off[t];
          for (int j = 0; j < 8; ++j) {
            v8 a;
            load8(a, p + j * kWidth);
            acc[j] += a * w;
          }
        }
        v8 p[4], q[2];
        for (int j = 0; j < 4; ++j)
          p[j] = MINER_SHUFFLE8(acc[2 * j], acc[2 * j + 1], 0, 8, 2, 10, 4, 12, 6, 14) +
                 MINER_SHUFFLE8(acc[2 * j], acc[2 * j + 1], 1, 9, 3, 11, 5, 13, 7, 15);
        for (int j = 0; j < 2; ++j)
          q[j] = MINER_SHUFFLE8(p[2 * j], p[2 * j + 1], 0, 1, 8, 9, 4, 5, 12, 13) +
                 MINER_SHUFFLE8(p[2 * j], p[2 * j + 1], 2, 3, 10, 11, 6, 7, 14, 15);
        v8 r;
        load8(r, out + x);
        r += sparse_part;
        r += MINER_SHUFFLE8(q[0], q[1], 0, 1, 2, 3, 8, 9, 10, 11) + MINER_SHUFFLE8(q[0], q[1], 4, 5, 6, 7, 12, 13, 14, 15);
        std::memcpy(out + x, &r, sizeof r);
      }
    }
}

}  // namespace miner::heuristic::kernels
