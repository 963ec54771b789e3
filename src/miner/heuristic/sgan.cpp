#include "miner/heuristic/sgan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <utility>

#include <omp.h>

#include <oneapi/dnnl/dnnl.hpp>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/text.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/heuristic/sgan_kernels.hpp"
#include "miner/heuristic/tensor_file.hpp"

namespace miner::heuristic {

extern const unsigned char kBuiltinSganWeights[];
extern const std::size_t kBuiltinSganWeightsSize;

namespace {

/// Single-threaded by design (the budget is per query on one core). oneDNN's OpenMP
/// runtime reads this thread's setting, and a convolution primitive keeps the thread count
/// it was created with: both the creation (Impl::build) and the execution (forward) run under
/// this guard, which restores the caller's setting on the way out. (Until session 6 only the
/// execution was guarded, and the primitives made at load time ran on two threads.)
class OneOpenMpThread {
 public:
  OneOpenMpThread() : previous_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~OneOpenMpThread() { omp_set_num_threads(previous_); }
  OneOpenMpThread(const OneOpenMpThread&) = delete;
  OneOpenMpThread& operator=(const OneOpenMpThread&) = delete;

 private:
  int previous_;
};

using dnnl::memory;
using Tag = memory::format_tag;
using Type = memory::data_type;

/// Channels-last activation buffer: value (voxel v, channel c) at data[v * channels + c],
/// voxel v = (z ny + y) nx + x — one sample, oneDNN's ndhwc.
struct Activation {
  int channels = 0;
  Eigen::Vector3i dims{0, 0, 0};  // nx, ny, nz
  std::vector<float> data;
  Activation() = default;
  Activation(int c, const Eigen::Vector3i& d) : channels(c), dims(d), data(static_cast<std::size_t>(c) * d.prod()) {}
  memory::desc desc() const { return {{1, channels, dims.z(), dims.y(), dims.x()}, Type::f32, Tag::ndhwc}; }
  std::size_t voxels() const { return static_cast<std::size_t>(dims.prod()); }
};

/// Copies one source (at dst's resolution) into channels [offset, offset + src.channels) of
/// dst. kChannels = src.channels when known at compile time (a fixed-size copy the compiler
/// turns into vector moves), else 0. dst may be a slab of planes of the full grid, starting at
/// plane z0. (Nothing is up-sampled: the decoder convolves on the coarse grid, UpsampledPart.)
template <std::size_t kChannels>
void copy_into(Activation& dst, const Activation& src, std::size_t offset, int z0) {
  const std::size_t sc = kChannels ? kChannels : static_cast<std::size_t>(src.channels);
  const Eigen::Vector3i d = dst.dims;
  const auto dc = static_cast<std::size_t>(dst.channels);
  const auto sx = static_cast<std::size_t>(src.dims.x()), sy = static_cast<std::size_t>(src.dims.y());
  float* out = dst.data.data() + offset;
  const float* in = src.data.data();
  for (int z = z0; z < z0 + d.z(); ++z)
    for (int y = 0; y < d.y(); ++y) {
      const std::size_t row = (static_cast<std::size_t>(z) * sy + static_cast<std::size_t>(y)) * sx;
      for (int x = 0; x < d.x(); ++x, out += dc) {
        const float* v = in + (row + static_cast<std::size_t>(x)) * sc;
        for (std::size_t ch = 0; ch < sc; ++ch) out[ch] = v[ch];
      }
    }
}

/// dst <- [srcs...] along channels, every source at dst's resolution; dst holds the planes
/// from z0 on.
void concat(Activation& dst, const std::vector<const Activation*>& srcs, int z0 = 0) {
  std::size_t offset = 0;  // channel offset of the current source in dst
  for (const Activation* src : srcs) {
    switch (src->channels) {  // the widths of the shipped width-8 network
      case 2: copy_into<2>(dst, *src, offset, z0); break;
      case 8: copy_into<8>(dst, *src, offset, z0); break;
      case 16: copy_into<16>(dst, *src, offset, z0); break;
      case 32: copy_into<32>(dst, *src, offset, z0); break;
      default: copy_into<0>(dst, *src, offset, z0);
    }
    offset += static_cast<std::size_t>(src->channels);
  }
}

/// dst <- max over 2x2x2 blocks of src (kernel = stride = 2; dst.dims = src.dims / 2). The
/// network's max-pools by 4 and 8 are this applied two and three times (max is associative).
void max_pool2(Activation& dst, const Activation& src) {
  const Eigen::Vector3i d = dst.dims, s = src.dims;
  const auto c = static_cast<std::size_t>(src.channels);
  const auto sx = static_cast<std::size_t>(s.x()), sxy = sx * static_cast<std::size_t>(s.y());
  float* out = dst.data.data();
  for (int z = 0; z < d.z(); ++z)
    for (int y = 0; y < d.y(); ++y)
      for (int x = 0; x < d.x(); ++x, out += c) {
        const float* v000 = src.data.data() + ((2 * static_cast<std::size_t>(z)) * sxy +
                                                (2 * static_cast<std::size_t>(y)) * sx + 2 * static_cast<std::size_t>(x)) * c;
        for (std::size_t ch = 0; ch < c; ++ch) {
          float m = v000[ch];
          for (const std::size_t off : {c, sx * c, sx * c + c, sxy * c, (sxy + 1) * c, (sxy + sx) * c, (sxy + sx + 1) * c})
            m = std::max(m, v000[off + ch]);
          out[ch] = m;
        }
      }
}

/// One 3x3x3 convolution (padding 1) with its fused activation.
struct Conv {
  dnnl::convolution_forward primitive;
  memory weights, bias, src, dst;  // src and dst wrap the Activation buffers
};

/// A 3x3x3 convolution (padding 1) with fused ReLU from src to dst, weights in the layout
/// oneDNN picks for the kernel it chooses.
dnnl::convolution_forward::primitive_desc relu_conv(const dnnl::engine& engine, const memory::desc& src,
                                                    const memory::desc& dst, int stride, bool accumulate = false,
                                                    int padding = 1) {
  const memory::dim cin = src.dims()[1], cout = dst.dims()[1];
  const dnnl::convolution_forward::desc cd(
      dnnl::prop_kind::forward_inference, dnnl::algorithm::convolution_direct, src,
      memory::desc({cout, cin, 3, 3, 3}, Type::f32, Tag::any), memory::desc({cout}, Type::f32, Tag::a), dst,
      {stride, stride, stride}, {padding, padding, padding}, {padding, padding, padding});
  dnnl::post_ops po;
  if (accumulate) po.append_sum(1.0f);  // dst = relu(conv(src) + bias + dst)
  po.append_eltwise(1.0f, dnnl::algorithm::eltwise_relu, 0.0f, 0.0f);
  dnnl::primitive_attr attr;
  attr.set_post_ops(po);
  return {cd, attr, engine};
}

/// c's primitive, weights (PyTorch's oidhw reordered to pd's layout) and bias; src and dst
/// are the caller's.
void set_conv(Conv& c, const dnnl::convolution_forward::primitive_desc& pd, const dnnl::engine& engine,
              dnnl::stream& stream, const Tensor& weights, const Tensor& bias) {
  c.primitive = dnnl::convolution_forward(pd);
  memory user(memory::desc(pd.weights_desc().dims(), Type::f32, Tag::oidhw), engine,
              const_cast<float*>(weights.values.data()));
  c.weights = memory(pd.weights_desc(), engine);
  dnnl::reorder(user, c.weights).execute(stream, user, c.weights);
  c.bias = memory(pd.bias_desc(), engine);
  std::copy(bias.values.begin(), bias.values.end(), static_cast<float*>(c.bias.get_data_handle()));
}

/// The part of a 3x3x3 convolution (padding 1) that reads an upsampled source, computed on the
/// source's own (coarse) grid. With up2 nearest-neighbour, fine voxel f = 2i + p (per axis,
/// parity p) reads coarse voxels i - 1, i, i (taps -1, 0, +1) when p = 0 and i, i, i + 1 when
/// p = 1: two distinct coarse taps per axis. So conv3(up2(x))[2i + p] =
/// sum over j in {0, 1}^3 of M_p[j] x[i + p + j - 1], M_p the 3x3x3 kernel's taps summed into
/// 2x2x2 by parity: one 2x2x2 convolution of x with padding 1 (output n + 1 per axis) whose
/// 8 cout output channels are the 8 parities, read back at q = i + p. 8 x 8 / 27 of the
/// multiply-adds of the fine convolution (on d2: 4.2 M instead of 14.2 M), and no upsampled
/// copy of x. Float sums in another order than PyTorch's: a few ulps (kReferenceTolerance).
struct UpsampledPart {
  dnnl::convolution_forward primitive;
  memory weights, src, dst;
  int cout = 0;
  Activation parities;  // 8 cout channels (parity p = 4 pz + 2 py + px first) on the (n + 1)^3 grid
};

/// Which of the two coarse taps fine tap k (0, 1, 2 for -1, 0, +1) reads at parity p.
constexpr int kCoarseTap[2][3] = {{0, 1, 1}, {0, 0, 1}};

/// Builds u from layer weights w (cout x cin_total x 3^3, PyTorch's oidhw) for the up-sampled
/// source x, the first x.channels input channels of the layer.
void set_upsampled_part(UpsampledPart& u, const dnnl::engine& engine, dnnl::stream& stream, const Tensor& w,
                        int cout, int cin_total, Activation& x) {
  const int cu = x.channels;
  u.cout = cout;
  u.parities = Activation(8 * cout, x.dims + Eigen::Vector3i::Ones());
  std::vector<float> merged(static_cast<std::size_t>(8 * cout * cu * 8), 0.0f);  // oidhw, 2x2x2
  for (int p = 0; p < 8; ++p) {
    const int pz = p >> 2, py = (p >> 1) & 1, px = p & 1;
    for (int o = 0; o < cout; ++o)
      for (int c = 0; c < cu; ++c)
        for (int t = 0; t < 27; ++t) {
          const int j = kCoarseTap[pz][t / 9] * 4 + kCoarseTap[py][t / 3 % 3] * 2 + kCoarseTap[px][t % 3];
          merged[static_cast<std::size_t>(((p * cout + o) * cu + c) * 8 + j)] +=
              w.values[static_cast<std::size_t>((o * cin_total + c) * 27 + t)];
        }
  }
  const memory::desc wd({8 * cout, cu, 2, 2, 2}, Type::f32, Tag::any);
  const dnnl::convolution_forward::primitive_desc pd(
      dnnl::convolution_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::convolution_direct,
                                      x.desc(), wd, u.parities.desc(), {1, 1, 1}, {1, 1, 1}, {1, 1, 1}),
      engine);
  u.primitive = dnnl::convolution_forward(pd);
  memory user(memory::desc({8 * cout, cu, 2, 2, 2}, Type::f32, Tag::oidhw), engine, merged.data());
  u.weights = memory(pd.weights_desc(), engine);
  dnnl::reorder(user, u.weights).execute(stream, user, u.weights);
  stream.wait();
  u.src = memory(x.desc(), engine, x.data.data());
  u.dst = memory(u.parities.desc(), engine, u.parities.data.data());
}

/// dst (cout channels on the fine grid) <- u's parities read back at each fine
/// voxel: dst[f][o] = parities[q][p cout + o], q_a = (f_a + 1) / 2, p_a = f_a mod 2.
void scatter_parities(Activation& dst, const UpsampledPart& u) {
  const Eigen::Vector3i d = dst.dims, qd = u.parities.dims;
  const auto co = static_cast<std::size_t>(u.cout), qc = static_cast<std::size_t>(u.parities.channels);
  float* out = dst.data.data();
  for (int z = 0; z < d.z(); ++z)
    for (int y = 0; y < d.y(); ++y) {
      const std::size_t row = (static_cast<std::size_t>((z + 1) / 2) * static_cast<std::size_t>(qd.y()) +
                               static_cast<std::size_t>((y + 1) / 2)) *
                              static_cast<std::size_t>(qd.x());
      const std::size_t pzy = static_cast<std::size_t>((z & 1) * 4 + (y & 1) * 2);
      for (int x = 0; x < d.x(); ++x, out += co) {
        const float* q = u.parities.data.data() + (row + static_cast<std::size_t>((x + 1) / 2)) * qc +
                         (pzy + static_cast<std::size_t>(x & 1)) * co;
        std::copy(q, q + co, out);
      }
    }
}

constexpr std::size_t kConvs = 9;
/// The last layer's tap products per voxel: 27, padded to 32 channels (zero filters) so each
/// voxel's row is 128 bytes and oneDNN's 1x1 kernel takes whole vector blocks (0.28 vs 0.34 ms).
constexpr int kTapChannels = 32;
constexpr const char* kLayers[kConvs] = {"enc1", "enc2", "enc3", "enc4", "mid1", "mid2", "dec3", "dec2", "dec1"};
constexpr int kStrides[kConvs] = {1, 2, 2, 2, 1, 1, 1, 1, 1};
constexpr std::size_t kFirstDecoder = 6;  // dec3, dec2, dec1 read an up-sampled source

}  // namespace

struct Sgan::Impl {
  /// Held by forward() while it fills the shared buffers below: calls on one Sgan from several
  /// threads run one at a time (twelfth campaign L6: two threads on one const Sgan gave 7 of
  /// 16 regions wrong, silently).
  std::mutex busy;
  std::string path;
  std::string sha256;  // of the weights file's bytes
  Json meta;
  SganArchitecture arch;
  dnnl::engine engine{dnnl::engine::kind::cpu, 0};
  // Buffers, in graph order (model.py's names; cat* are the concatenated conv inputs).
  Activation x0, cond1, a1, c2, a2, cat2, c4, a3, cat3, c8, a4, sigma, cat4, m1, m2, d3, d2, catd1, out;
  // The decoder's convolutions split in two: the up-sampled source's part on its coarse grid
  // (UpsampledPart: m2 for dec3, d3 for dec2, d2 for dec1) and the skip inputs' part (cat3,
  // cat2, [a1, E/2, S[, B]]) on the fine grid, which adds the first (oneDNN's sum post-op; for dec1
  // in shift_sum_plane). Nothing up-sampled is ever copied.
  std::array<UpsampledPart, 3> up;
  // The last layer streams plane by plane (catd1 is one plane of its input, taps a ring of three
  // planes of its tap products), so its 7.6 MB of full-grid buffers stay out of the caches.
  Activation taps;                      // 27 tap products per voxel (+5 zero channels), 3 planes
  std::vector<float> last_tap_weights;  // [kTapChannels][cin], oidhw of the 1x1x1 tap convolution
  float last_bias = 0.0f;
  std::vector<float> plane_base;        // one plane of the logits' start: bias + d2's part (up[2])
  dnnl::eltwise_forward sigmoid;        // R = sigmoid(logits), in place on out
  memory out_memory;
  // MINER's own kernels for enc1 and dec1's skip part (sgan_kernels.hpp; width 8 and
  // Sgan::Kernels::kFastest): N and the conditions (E/2, S[, the blocked bits]) on a padded grid,
  // the voxels where a condition is nonzero, and a1 channels-last on the padded grid, which enc2
  // (oneDNN) reads with padding 0.
  bool own_kernels = false;
  std::vector<float> noise_padded, a1_padded;
  std::vector<float> noise_grid;  // a query's N, voxel order (predict)
  std::vector<std::vector<float>> condition_padded;  // one planar padded grid per condition
  std::vector<const float*> condition_pointers;
  std::vector<kernels::SparseInput> sparse;
  std::vector<float> first_weights, first_bias, skip_weights;
  std::array<Conv, kConvs> conv;
  std::array<std::pair<Activation*, Activation*>, kConvs> io;

  /// Starts a query's input (the sparse list is rebuilt by set_input).
  void begin_input() { sparse.clear(); }

  /// Voxel (x, y, z), index v, of the input: E/2 = e, S = s, N = noise, the blocked bits
  /// 1 - P_a in pass[0..2] (when the network reads P); cond1 = (E/2, S[, B]) and, with the own
  /// kernels, N and cond1 on the padded grid and cond1 in the sparse list when nonzero; else
  /// x0 = (cond1, N) channels-last.
  void set_input(int x, int y, int z, std::size_t v, float e, float s, float noise, const float* pass = nullptr) {
    if (own_kernels) {
      const Eigen::Vector3i d = cond1.dims;
      kernels::SparseInput in{((z + 1) * (d.y() + 2) + y + 1) * (d.x() + 2) + x + 1, {e, s, 0.0F, 0.0F, 0.0F}};
      for (int a = 0; a < arch.passability_channels; ++a) in.condition[2 + a] = pass[a];
      write_own_input(v, in, noise);
      return;
    }
    const auto c = static_cast<std::size_t>(x0.channels);
    x0.data[c * v] = e;
    x0.data[c * v + 1] = s;
    for (int a = 0; a < arch.passability_channels; ++a) x0.data[c * v + 2 + static_cast<std::size_t>(a)] = pass[a];
    x0.data[c * v + c - 1] = noise;
    const auto nc = static_cast<std::size_t>(cond1.channels);
    cond1.data[nc * v] = e;
    cond1.data[nc * v + 1] = s;
    for (int a = 0; a < arch.passability_channels; ++a) cond1.data[nc * v + 2 + static_cast<std::size_t>(a)] = pass[a];
  }

  /// One voxel of the own kernels' input, the one writer set_input and set_input_encoded share:
  /// its conditions (E/2, S, the blocked bits) in the padded planes and in cond1 (voxel v), its
  /// noise, and the sparse list when a condition, as the float the kernels read, is nonzero.
  void write_own_input(std::size_t v, const kernels::SparseInput& in, float noise) {
    const auto p = static_cast<std::size_t>(in.padded);
    noise_padded[p] = noise;
    float* cv = cond1.data.data() + v * condition_padded.size();
    bool nonzero = false;
    for (std::size_t c = 0; c < condition_padded.size(); ++c) {
      condition_padded[c][p] = in.condition[c];
      cv[c] = in.condition[c];
      nonzero = nonzero || in.condition[c] != 0.0F;
    }
    if (nonzero) sparse.push_back(in);
  }

  /// The dataset encoding as the own kernels' input (set_input's effect for every voxel, in one
  /// pass without its per-voxel branching): E/2 = scale E, S, the blocked bits 1 - P_a when
  /// the network reads P, and N = noise (x fastest).
  void set_input_encoded(const std::uint8_t* environment, const std::uint8_t* state, const std::uint8_t* passability,
                         float scale, const float* noise_in) {
    sparse.clear();
    const Eigen::Vector3i d = cond1.dims;
    const bool reads_p = arch.passability_channels != 0;
    std::size_t v = 0;
    for (int z = 0; z < d.z(); ++z)
      for (int y = 0; y < d.y(); ++y) {
        int padded = ((z + 1) * (d.y() + 2) + y + 1) * (d.x() + 2) + 1;
        for (int x = 0; x < d.x(); ++x, ++v, ++padded) {
          // The blocked bits: 0 on free cells (train.py's to_inputs).
          const unsigned blocked = reads_p ? ~static_cast<unsigned>(passability[v]) & kPassAll : 0U;
          write_own_input(v,
                          kernels::SparseInput{padded,
                                               {scale * static_cast<float>(environment[v]), static_cast<float>(state[v]),
                                                static_cast<float>(blocked & 1U), static_cast<float>((blocked >> 1) & 1U),
                                                static_cast<float>((blocked >> 2) & 1U)}},
                          noise_in[v]);
        }
      }
  }

  /// Calls f(x, y, z, v) for every voxel in index order (x fastest).
  template <class F>
  void for_voxels(F&& f) const {
    const Eigen::Vector3i d = cond1.dims;
    std::size_t v = 0;
    for (int z = 0; z < d.z(); ++z)
      for (int y = 0; y < d.y(); ++y)
        for (int x = 0; x < d.x(); ++x, ++v) f(x, y, z, v);
  }

  /// One plane of the logits' start: bias + d2's up-sampled part (up[2]).
  void logit_base_plane(int z, float* dst) const;

  /// The last layer's bias and R = sigmoid(logits), in place on out.
  void set_output(float bias) {
    last_bias = bias;
    out_memory = memory(out.desc(), engine, out.data.data());
    sigmoid = dnnl::eltwise_forward(dnnl::eltwise_forward::primitive_desc(
        dnnl::eltwise_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::eltwise_logistic, out.desc(),
                                    0.0f, 0.0f),
        engine));
  }

  /// sigma, constant over the bottleneck's grid (nothing when the network has no scale input).
  void set_scale(const std::vector<float>& scale) {
    if (sigma.channels == 0) return;
    if (scale.size() != static_cast<std::size_t>(sigma.channels))
      throw Error("sgan: the network takes a scale input of " + std::to_string(sigma.channels) + " values, given " +
                  std::to_string(scale.size()));
    for (std::size_t v = 0; v < sigma.voxels(); ++v)
      std::copy(scale.begin(), scale.end(), sigma.data.begin() + static_cast<std::ptrdiff_t>(v * scale.size()));
  }

  /// The generator on the input set by set_input: R, one probability per voxel.
  std::vector<float> run();

  /// Plane z of the logits: out[v] = bias + sum over taps t = (dz, dy, dx) of
  /// Y_{z+dz}[v + (dy-1, dx-1)][t], with Y_{z-1}, Y_z, Y_{z+1} the tap products of the planes
  /// around z (nullptr off the grid), skipping taps outside the grid (zero padding): the 3x3x3
  /// last layer, finished.
  void shift_sum_plane(int z, const std::array<const float*, 3>& planes);

  void build(const TensorFile& f, Sgan::Kernels kernels);
};

void Sgan::Impl::build(const TensorFile& f, Sgan::Kernels which) {
  const JsonField a(f.meta, "meta", f.path);
  a.only_keys({"architecture", "final", "training"});
  // The training record is free-form provenance, but a record: an object (issue 20, S7).
  for (const char* key : {"final", "training"})
    if (a.has(key) && !a.at(key).value().is_object()) a.at(key).fail("must be an object (the training record)");
  const JsonField ar = a.at("architecture");
  ar.only_keys({"name", "width", "dims", "environment_scale", "threshold", "threshold_rule", "layers", "scale_channels",
                "scale_divisor", "passability_channels"});
  if (ar.at("name").string() != "sgan-unet4") ar.at("name").fail("unknown architecture (expected sgan-unet4)");
  if (ar.has("layers")) {  // optional (the tensors name the layers); when given it must be right
    const std::vector<std::string> expected{"enc1", "enc2", "enc3", "enc4", "mid1", "mid2", "dec3", "dec2", "dec1"};
    const JsonField layers = ar.at("layers");
    std::vector<std::string> given;
    for (std::size_t i = 0; i < layers.array_size(); ++i) given.push_back(layers.at(i).string());
    if (given != expected) layers.fail("must list sgan-unet4's nine layers enc1 ... dec1 in order");
  }
  arch.width = ar.at("width").integer();
  if (arch.width < 1 || arch.width > 256) ar.at("width").fail("must be in [1, 256]");
  const JsonField dims = ar.at("dims");
  arch.dims = Eigen::Vector3i(dims.at(0).integer(), dims.at(1).integer(), dims.at(2).integer());
  if ((arch.dims.array() < 8).any() || (arch.dims.array() > 256).any() || arch.dims.x() % 8 != 0 ||
      arch.dims.y() % 8 != 0 || arch.dims.z() % 8 != 0)
    dims.fail("each must be a multiple of 8 in [8, 256]");
  // E in {0, 1, 2} enters the network as E x scale: a scale outside (0, 1] is no encoding the
  // network was trained on (issue 20: -1e300 was accepted).
  // One range in one message: (0, 1] (issue 20, eighth campaign U5: -1 was told "[0, 1]" and
  // 0 then "must be positive").
  arch.environment_scale = ar.at("environment_scale").number();
  if (!(arch.environment_scale > 0.0 && arch.environment_scale <= 1.0))
    ar.at("environment_scale").fail("must be in (0, 1], got " + exact_number(arch.environment_scale));
  arch.threshold = ar.at("threshold").number();
  if (!(arch.threshold > 0.0 && arch.threshold < 1.0)) ar.at("threshold").fail("must be in (0, 1)");
  // Absent in the files written before the widest rule (REQ-HEUR-016): fixed.
  if (ar.has("threshold_rule")) {
    const std::string rule = ar.at("threshold_rule").string();
    if (rule == "widest") arch.threshold_rule = ThresholdRule::kWidest;
    else if (rule != "fixed") ar.at("threshold_rule").fail("must be \"fixed\" or \"widest\", not \"" + rule + "\"");
  }
  // Absent in the files written before the scale input (one family, one scale).
  arch.scale_channels = ar.has("scale_channels") ? ar.at("scale_channels").integer() : 0;
  if (arch.scale_channels != 0 && arch.scale_channels != 3) ar.at("scale_channels").fail("must be 0 or 3 (x, y, z)");
  if (arch.scale_channels != 0) {
    // sigma spans [-1, 1] for cells of 1/16 to 16 radii at divisor 4; outside [1, 64] the
    // inputs would be squashed to nothing or blown up.
    arch.scale_divisor = ar.at("scale_divisor").number_in(1.0, 64.0);
  } else if (ar.has("scale_divisor")) {
    // The two keys disagree; which one is wrong is the tensors' to say (mid1's input width):
    // name both (issue 20, fifth campaign: "scale_channels: 0" was blamed on scale_divisor).
    ar.at("scale_divisor").fail(std::string("is given, but scale_channels is ") +
                                (ar.has("scale_channels") ? "0" : "absent") +
                                ": a network without the scale input has no divisor (set scale_channels to 3 if the "
                                "network was trained with the scale input, else drop scale_divisor)");
  }
  // Absent in the files written before channel P (dataset v1).
  arch.passability_channels = ar.has("passability_channels") ? ar.at("passability_channels").integer() : 0;
  if (arch.passability_channels != 0 && arch.passability_channels != 3)
    ar.at("passability_channels").fail("must be 0 or 3 (x, y, z)");

  const int w = arch.width;
  const Eigen::Vector3i n1 = arch.dims, n2 = n1 / 2, n4 = n1 / 4, n8 = n1 / 8;
  // The condition channels c_k: E/2, S and P's three bits when the network reads them.
  const int nc = 2 + arch.passability_channels;
  own_kernels = which == Sgan::Kernels::kFastest && w == kernels::kWidth && nc <= kernels::kMaxConditions;
  const Eigen::Vector3i padded = n1 + Eigen::Vector3i::Constant(2);
  if (own_kernels) {
    noise_padded.assign(static_cast<std::size_t>(padded.prod()), 0.0f);
    a1_padded.assign(static_cast<std::size_t>(padded.prod()) * kernels::kWidth, 0.0f);
    condition_padded.assign(static_cast<std::size_t>(nc), std::vector<float>(static_cast<std::size_t>(padded.prod()), 0.0f));
    condition_pointers.clear();
    for (const auto& plane : condition_padded) condition_pointers.push_back(plane.data());
  }
  x0 = Activation(nc + 1, own_kernels ? Eigen::Vector3i(0, 0, 0) : n1);  // oneDNN's enc1 input only
  cond1 = Activation(nc, n1);
  a1 = Activation(w, n1);
  c2 = Activation(nc, n2);
  a2 = Activation(2 * w, n2);
  cat2 = Activation(2 * w + nc, n2);
  c4 = Activation(nc, n4);
  a3 = Activation(4 * w, n4);
  cat3 = Activation(4 * w + nc, n4);
  c8 = Activation(nc, n8);
  a4 = Activation(4 * w, n8);
  sigma = Activation(arch.scale_channels, n8);
  cat4 = Activation(4 * w + nc + arch.scale_channels, n8);
  m1 = Activation(4 * w, n8);
  m2 = Activation(4 * w, n8);
  d3 = Activation(2 * w, n4);
  d2 = Activation(2 * w, n2);
  catd1 = Activation(w + nc, Eigen::Vector3i(n1.x(), n1.y(), 1));
  out = Activation(1, n1);
  io = {{{&x0, &a1}, {&a1, &a2}, {&cat2, &a3}, {&cat3, &a4}, {&cat4, &m1}, {&m1, &m2}, {&cat3, &d3},
         {&cat2, &d2}, {&catd1, &out}}};
  // The up-sampled source of dec3, dec2, dec1 (layers 6, 7, 8), ahead of their skip inputs.
  const std::array<Activation*, 3> upsampled{&m2, &d3, &d2};

  dnnl::stream stream(engine);
  for (std::size_t l = 0; l < kConvs; ++l) {
    Activation& src = *io[l].first;
    Activation& dst = *io[l].second;
    const int cout = dst.channels;
    const bool decoder = l >= kFirstDecoder;
    const int cu = decoder ? upsampled[l - kFirstDecoder]->channels : 0;  // up-sampled channels
    const int cin = cu + src.channels;
    const Tensor& full = f.at(std::string(kLayers[l]) + ".weight", {cout, cin, 3, 3, 3});
    const Tensor& bt = f.at(std::string(kLayers[l]) + ".bias", {cout});
    for (const auto* t : {&full, &bt})
      for (float v : t->values)
        if (!std::isfinite(v)) throw Error(f.path + ": layer " + kLayers[l] + " has a non-finite weight");
    Tensor skip_part;  // a decoder layer's weights of its skip inputs (channels cu on)
    if (decoder) {
      set_upsampled_part(up[l - kFirstDecoder], engine, stream, full, cout, cin, *upsampled[l - kFirstDecoder]);
      skip_part.shape = {cout, src.channels, 3, 3, 3};
      for (int o = 0; o < cout; ++o)
        skip_part.values.insert(skip_part.values.end(),
                                full.values.begin() + static_cast<std::ptrdiff_t>((o * cin + cu) * 27),
                                full.values.begin() + static_cast<std::ptrdiff_t>((o + 1) * cin * 27));
    }
    const Tensor& wt = decoder ? skip_part : full;
    const bool last = l + 1 == kConvs;
    Conv& c = conv[l];
    if (own_kernels && (l == 0 || last)) {  // sgan_kernels.cpp
      if (l == 0) {
        first_weights = wt.values;
        first_bias = bt.values;
      } else {
        skip_weights = wt.values;
        set_output(bt.values[0]);
      }
      continue;
    }
    if (own_kernels && l == 1) {  // enc2 reads a1 on the padded grid: padding 0
      const memory::desc src_padded({1, kernels::kWidth, padded.z(), padded.y(), padded.x()}, Type::f32, Tag::ndhwc);
      set_conv(c, relu_conv(engine, src_padded, dst.desc(), kStrides[l], false, 0), engine, stream, wt, bt);
      c.src = memory(src_padded, engine, a1_padded.data());
      c.dst = memory(dst.desc(), engine, dst.data.data());
      continue;
    }
    if (last) {
      // A single output channel keeps oneDNN's kernels ~5 % busy; instead a 1x1x1
      // convolution computes, per voxel u, the 27 tap products Y[u][t] = sum_c W[0][c][t]
      // in[u][c] (a GEMM), and shift_sum_plane() adds Y[v + offset_t][t] over the taps.
      taps = Activation(kTapChannels, Eigen::Vector3i(n1.x(), n1.y(), 3));
      const memory::desc taps_plane({1, kTapChannels, 1, n1.y(), n1.x()}, Type::f32, Tag::ndhwc);
      const dnnl::convolution_forward::primitive_desc pd(
          dnnl::convolution_forward::desc(dnnl::prop_kind::forward_inference, dnnl::algorithm::convolution_direct,
                                          src.desc(), memory::desc({kTapChannels, src.channels, 1, 1, 1}, Type::f32, Tag::any),
                                          taps_plane, {1, 1, 1}, {0, 0, 0}, {0, 0, 0}),
          engine);
      c.primitive = dnnl::convolution_forward(pd);
      const int cs = src.channels;
      std::vector<float> tap_weights(static_cast<std::size_t>(kTapChannels * cs), 0.0f);
      for (int ch = 0; ch < cs; ++ch)
        for (int t = 0; t < 27; ++t)
          tap_weights[static_cast<std::size_t>(t * cs + ch)] = wt.values[static_cast<std::size_t>(ch * 27 + t)];
      last_tap_weights = std::move(tap_weights);
      memory user(memory::desc({kTapChannels, cs, 1, 1, 1}, Type::f32, Tag::oidhw), engine, last_tap_weights.data());
      c.weights = memory(pd.weights_desc(), engine);
      dnnl::reorder(user, c.weights).execute(stream, user, c.weights);
      set_output(bt.values[0]);
      plane_base.assign(static_cast<std::size_t>(n1.x() * n1.y()), 0.0f);
      c.src = memory(src.desc(), engine, src.data.data());
      c.dst = memory(taps_plane, engine, taps.data.data());  // moved along the ring in run()
      continue;
    }
    set_conv(c, relu_conv(engine, src.desc(), dst.desc(), kStrides[l], decoder), engine, stream, wt, bt);
    c.src = memory(src.desc(), engine, src.data.data());
    c.dst = memory(dst.desc(), engine, dst.data.data());
  }
  stream.wait();
  // Every tensor of the file must be one the graph uses: a file for another graph that
  // happens to contain these names is still refused.
  if (f.tensors.size() != 2 * kConvs)
    throw Error(f.path + ": " + std::to_string(f.tensors.size()) + " tensors, the sgan-unet4 graph has " +
                std::to_string(2 * kConvs));
}

void Sgan::Impl::logit_base_plane(int z, float* dst) const {
  // scatter_parities for one output channel: parity p = 4 pz + 2 py + px at q = (f + 1) / 2.
  const Eigen::Vector3i d = out.dims;
  const UpsampledPart& u = up[2];
  const Eigen::Vector3i qd = u.parities.dims;
  for (int yy = 0; yy < d.y(); ++yy) {
    const float* row = u.parities.data.data() +
                       ((static_cast<std::ptrdiff_t>((z + 1) / 2) * qd.y() + (yy + 1) / 2) * qd.x()) * 8 +
                       (z & 1) * 4 + (yy & 1) * 2;
    for (int x = 0; x < d.x(); ++x) *dst++ = last_bias + row[((x + 1) / 2) * 8 + (x & 1)];
  }
}

void Sgan::Impl::shift_sum_plane(int z, const std::array<const float*, 3>& planes) {
  const Eigen::Vector3i d = out.dims;
  constexpr std::ptrdiff_t C = kTapChannels;  // a constant: fixed-stride loads below
  const std::ptrdiff_t sy = C * d.x();
  // Where tap t = (dz+1) 9 + (dy+1) 3 + (dx+1) of voxel v lies: tap[t][v C].
  std::array<const float*, 27> tap{};
  for (int t = 0; t < 27; ++t)
    if (planes[static_cast<std::size_t>(t / 9)])
      tap[static_cast<std::size_t>(t)] = planes[static_cast<std::size_t>(t / 9)] + (t / 3 % 3 - 1) * sy + (t % 3 - 1) * C + t;
  float* o = out.data.data() + static_cast<std::ptrdiff_t>(z) * d.x() * d.y();
  logit_base_plane(z, plane_base.data());
  const float* base = plane_base.data();
  // Border voxels: taps outside the grid are skipped; the sum runs in tap order as below.
  auto border = [&](int x, int yy) {
    const std::ptrdiff_t v = static_cast<std::ptrdiff_t>(yy) * d.x() + x;
    float sum = base[v];
    for (int dz = -1; dz <= 1; ++dz) {
      if (!planes[static_cast<std::size_t>(dz + 1)]) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        if (yy + dy < 0 || yy + dy >= d.y()) continue;
        for (int dx = -1; dx <= 1; ++dx)
          if (x + dx >= 0 && x + dx < d.x()) sum += tap[static_cast<std::size_t>((dz + 1) * 9 + (dy + 1) * 3 + dx + 1)][v * C];
      }
    }
    o[v] = sum;
  };
  // Interior voxels, kChains at a time: independent sums hide the add latency (one voxel's 27
  // adds form a dependent chain); each voxel still adds its taps in tap order.
  constexpr int kChains = 4;  // 0.15 ms for the 32^3 grid here, vs 0.25 ms one voxel at a time
  const bool inner_plane = planes[0] && planes[2];
  for (int yy = 0; yy < d.y(); ++yy) {
    if (!inner_plane || yy == 0 || yy + 1 == d.y() || d.x() < 3) {
      for (int x = 0; x < d.x(); ++x) border(x, yy);
      continue;
    }
    border(0, yy);
    int x = 1;
    for (; x + kChains < d.x(); x += kChains) {
      const std::ptrdiff_t v = static_cast<std::ptrdiff_t>(yy) * d.x() + x;
      std::array<float, kChains> acc;
      std::copy(base + v, base + v + kChains, acc.begin());
      for (std::size_t t = 0; t < 27; ++t)
        for (int j = 0; j < kChains; ++j) acc[static_cast<std::size_t>(j)] += tap[t][(v + j) * C];
      std::copy(acc.begin(), acc.end(), o + v);
    }
    for (; x + 1 < d.x(); ++x) {
      const std::ptrdiff_t v = static_cast<std::ptrdiff_t>(yy) * d.x() + x;
      float sum = base[v];
      for (std::size_t t = 0; t < 27; ++t) sum += tap[t][v * C];
      o[v] = sum;
    }
    border(d.x() - 1, yy);
  }
}

Sgan::Sgan(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Sgan::Impl& Sgan::live() const {
  if (!impl_) throw Error("Sgan: used after being moved from");  // tenth campaign L21
  return *impl_;
}
Sgan::~Sgan() = default;
Sgan::Sgan(Sgan&&) noexcept = default;
Sgan& Sgan::operator=(Sgan&&) noexcept = default;

Sgan Sgan::from_bytes(const std::string& blob, const std::string& origin, Kernels kernels) {
  const TensorFile f = parse_tensor_file(blob, origin, "sgan-weights");
  auto impl = std::make_unique<Impl>();
  impl->path = origin;
  impl->sha256 = sha256_hex(blob);
  impl->meta = f.meta;
  try {
    const OneOpenMpThread one_thread;  // the primitives keep the thread count they are made with
    impl->build(f, kernels);
  } catch (const dnnl::error& e) {
    throw Error(origin + ": oneDNN refused the network (" + e.what() + ")");
  }
  return Sgan(std::move(impl));
}

Sgan Sgan::load(const std::string& path) { return from_bytes(read_file_bytes(path, "the sGAN weights file"), path); }

Sgan Sgan::load_or_builtin(const std::string& path) { return path.empty() ? builtin() : load(path); }

Sgan Sgan::builtin() {
  return from_bytes(std::string(reinterpret_cast<const char*>(kBuiltinSganWeights), kBuiltinSganWeightsSize),
                    "builtin fixtures/sgan/sgan.bin");
}

const SganArchitecture& Sgan::architecture() const { return live().arch; }
const Json& Sgan::meta() const { return live().meta; }
const std::string& Sgan::path() const { return live().path; }
const std::string& Sgan::sha256() const { return live().sha256; }
bool Sgan::own_kernels() const { return live().own_kernels; }

namespace {

/// A probability outside [0, 1] or not a number means weights (or, for forward(), inputs) the
/// network cannot carry (e.g. entries near FLT_MAX overflow a layer); the threshold would drop
/// such cells silently and leave a 2-cell region (issue 20), so the answer is checked before it
/// is returned.
std::vector<float> checked_probabilities(const std::string& path, std::vector<float> r, const char* cause) {
  const std::size_t v = first_non_probability(r);
  if (v != r.size())
    throw Error(path + ": the network's output at cell " + std::to_string(v) + " is " + std::to_string(r[v]) +
                ", not a probability: " + cause);
  return r;
}

/// Fourteenth campaign L3: forward() ran NaN inputs through and returned NaN probabilities.
void require_finite_input(const std::vector<float>& values, const char* name) {
  for (std::size_t v = 0; v < values.size(); ++v)
    if (!std::isfinite(values[v]))
      throw Error(std::string("sgan: input ") + name + "[" + std::to_string(v) + "] is " + std::to_string(values[v]) +
                  ", not a finite number");
}

constexpr const char* kWeightsOverflow = "the weights overflow a layer (check the file's tensors)";

}  // namespace

std::vector<float> Sgan::forward(const std::vector<float>& env, const std::vector<float>& state,
                                 const std::vector<float>& noise, const std::vector<float>& scale,
                                 const std::vector<float>& passability) const {
  Impl& g = live();
  const std::lock_guard<std::mutex> one_query(g.busy);
  const std::size_t n = g.cond1.voxels();
  if (env.size() != n || state.size() != n || noise.size() != n)
    throw Error("sgan: inputs must have " + std::to_string(n) + " cells each (the weights' grid)");
  const auto pc = static_cast<std::size_t>(g.arch.passability_channels);
  if (pc != 0 && passability.size() != pc * n)
    throw Error("sgan: the network reads P: " + std::to_string(pc) + " x " + std::to_string(n) + " values, given " +
                std::to_string(passability.size()));
  require_finite_input(env, "env");
  require_finite_input(state, "state");
  require_finite_input(noise, "noise");
  require_finite_input(scale, "scale");
  require_finite_input(passability, "passability");
  g.set_scale(scale);
  g.begin_input();
  g.for_voxels([&](int x, int y, int z, std::size_t v) {
    float p[3] = {0.0F, 0.0F, 0.0F};
    for (std::size_t a = 0; a < pc; ++a) p[a] = passability[a * n + v];
    g.set_input(x, y, z, v, env[v], state[v], noise[v], p);
  });
  return checked_probabilities(g.path, g.run(), "a layer overflowed (check the inputs' magnitudes and the file's tensors)");
}

std::vector<float> scale_input(const world::Box& bounds, const Eigen::Vector3i& dims, double robot_radius,
                               double divisor) {
  if (!(std::isfinite(robot_radius) && robot_radius >= 0.0))
    throw Error("sgan: the robot radius must be >= 0 and finite for the scale input");
  if (!(std::isfinite(divisor) && divisor > 0.0))
    throw Error("sgan: the scale divisor must be positive and finite, got " + exact_number(divisor));
  if ((dims.array() < 1).any()) throw Error("sgan: every grid dimension must be at least 1 for the scale input");
  std::vector<float> sigma(3);
  for (int a = 0; a < 3; ++a) {
    const double cell = (bounds.max[a] - bounds.min[a]) / dims[a];
    if (!(std::isfinite(cell) && cell > 0.0)) throw Error("sgan: the grid's cells must have a positive finite size");
    // A point robot (radius 0) has cells infinitely many radii wide: the limit.
    const double v = robot_radius > 0.0 ? std::log2(cell / robot_radius) / divisor : kScaleLimit;
    sigma[static_cast<std::size_t>(a)] = static_cast<float>(std::clamp(v, -kScaleLimit, kScaleLimit));
  }
  return sigma;
}

std::vector<float> Sgan::Impl::run() {
  Impl& g = *this;
  const OneOpenMpThread one_thread;
  dnnl::stream stream(g.engine);
  auto run = [&](std::size_t l) {
    g.conv[l].primitive.execute(stream, {{DNNL_ARG_SRC, g.conv[l].src},
                                         {DNNL_ARG_WEIGHTS, g.conv[l].weights},
                                         {DNNL_ARG_BIAS, g.conv[l].bias},
                                         {DNNL_ARG_DST, g.conv[l].dst}});
    stream.wait();
  };
  const Eigen::Vector3i n1 = g.out.dims;
  const int dims[3] = {n1.x(), n1.y(), n1.z()};
  if (g.own_kernels)
    kernels::first_layer(dims, g.cond1.channels, g.noise_padded.data(), g.sparse, g.first_weights.data(),
                         g.first_bias.data(), g.a1_padded.data());
  else
    run(0);  // a1
  run(1);  // a2
  max_pool2(g.c2, g.cond1);
  max_pool2(g.c4, g.c2);
  max_pool2(g.c8, g.c4);
  concat(g.cat2, {&g.a2, &g.c2});
  run(2);  // a3
  concat(g.cat3, {&g.a3, &g.c4});
  run(3);  // a4
  concat(g.cat4, {&g.a4, &g.c8, &g.sigma});
  run(4);  // m1
  run(5);  // m2
  auto run_up = [&](UpsampledPart& u) {
    u.primitive.execute(stream, {{DNNL_ARG_SRC, u.src}, {DNNL_ARG_WEIGHTS, u.weights}, {DNNL_ARG_DST, u.dst}});
    stream.wait();
  };
  run_up(g.up[0]);
  scatter_parities(g.d3, g.up[0]);
  run(6);  // d3 = relu(conv(cat3) + bias + the up-sampled part)
  run_up(g.up[1]);
  scatter_parities(g.d2, g.up[1]);
  run(7);  // d2
  run_up(g.up[2]);  // d2's part of the logits
  if (g.own_kernels) {
    const std::size_t plane = static_cast<std::size_t>(n1.x() * n1.y());
    for (int z = 0; z < n1.z(); ++z) g.logit_base_plane(z, g.out.data.data() + static_cast<std::size_t>(z) * plane);
    kernels::last_layer_skip(dims, g.cond1.channels, g.a1_padded.data(), g.condition_pointers.data(),
                             g.skip_weights.data(), g.out.data.data());
    g.sigmoid.execute(stream, {{DNNL_ARG_SRC, g.out_memory}, {DNNL_ARG_DST, g.out_memory}});
    stream.wait();  // R
    return g.out.data;
  }
  // The last layer, plane by plane: the tap products of plane p go to ring slot p % 3, and
  // plane p - 1 of the logits is finished once planes p - 2, p - 1 and p are there.
  const int nz = g.out.dims.z();
  const std::size_t plane = g.taps.voxels() / 3 * static_cast<std::size_t>(kTapChannels);
  const auto slot = [&](int p) -> float* { return g.taps.data.data() + static_cast<std::size_t>(p % 3) * plane; };
  for (int p = 0; p < nz; ++p) {
    concat(g.catd1, {&g.a1, &g.cond1}, p);
    g.conv[8].dst.set_data_handle(slot(p));
    run(8);  // tap products of plane p
    if (p >= 1) g.shift_sum_plane(p - 1, {p >= 2 ? slot(p - 2) : nullptr, slot(p - 1), slot(p)});
  }
  g.shift_sum_plane(nz - 1, {slot(nz - 2), slot(nz - 1), nullptr});  // logits
  g.sigmoid.execute(stream, {{DNNL_ARG_SRC, g.out_memory}, {DNNL_ARG_DST, g.out_memory}});
  stream.wait();  // R
  return g.out.data;
}

std::vector<float> Sgan::predict(const std::vector<std::uint8_t>& environment, const std::vector<std::uint8_t>& state,
                                 const std::vector<std::uint8_t>& passability, const world::Box& bounds,
                                 double robot_radius, Rng& rng) const {
  Impl& g = live();
  const std::lock_guard<std::mutex> one_query(g.busy);
  const std::size_t n = g.cond1.voxels();
  if (environment.size() != n || state.size() != n)
    throw Error("sgan: E and S must have " + std::to_string(n) + " cells each (the weights' grid)");
  const int pc = g.arch.passability_channels;
  if (pc != 0 && passability.size() != n)
    throw Error("sgan: the network reads P: " + std::to_string(n) + " cells, given " + std::to_string(passability.size()));
  // The encoded channels' levels (REQ-HEUR-002).
  require_levels(environment, kSolid, "sgan: E");
  require_levels(state, 1, "sgan: S");
  if (pc != 0) require_levels(passability, kPassAll, "sgan: P");
  if (g.arch.scale_channels != 0) g.set_scale(scale_input(bounds, g.arch.dims, robot_radius, g.arch.scale_divisor));
  const auto scale = static_cast<float>(g.arch.environment_scale);
  // N(0, 1) in voxel order (x fastest), one bulk draw of the query's stream.
  g.noise_grid.resize(n);
  rng.fill_normal_ziggurat(g.noise_grid.data(), n);
  if (g.own_kernels) {
    g.set_input_encoded(environment.data(), state.data(), passability.data(), scale, g.noise_grid.data());
    return checked_probabilities(g.path, g.run(), kWeightsOverflow);
  }
  g.begin_input();
  g.for_voxels([&](int x, int y, int z, std::size_t v) {
    float p[3] = {0.0F, 0.0F, 0.0F};
    // The network reads the blocked bits 1 - P_a (train.py's to_inputs): 0 on free cells.
    for (int a = 0; a < pc; ++a) p[a] = 1.0F - static_cast<float>((passability[v] >> a) & 1U);
    g.set_input(x, y, z, v, scale * static_cast<float>(environment[v]), static_cast<float>(state[v]),
                g.noise_grid[v], p);
  });
  return checked_probabilities(g.path, g.run(), kWeightsOverflow);
}

std::vector<double> reference_errors(const Sgan& sgan, const std::string& reference_path) {
  const TensorFile ref = read_tensor_file(reference_path, "sgan-reference");
  const Eigen::Vector3i d = sgan.architecture().dims;
  const std::vector<int> shape = {d.z(), d.y(), d.x()};
  const JsonField meta(ref.meta, "meta", reference_path);
  // The keys train.py and reference.py write; a misspelt one is refused, as in the weights' meta
  // (issue 20, sixth campaign U7: "sampels" was ignored).
  meta.only_keys({"samples", "weights"});
  if (meta.has("weights")) (void)meta.at("weights").string();
  const JsonField samples = meta.at("samples");
  if (samples.integer() < 1) samples.fail("must be >= 1");
  // Every tensor belongs to a sample the meta counts: one of a sample past meta.samples would be
  // left unchecked (seventh campaign C11: a second sample was ignored without notice).
  for (const auto& [name, tensor] : ref.tensors) {
    const std::size_t dot = name.find('.');
    const std::string index = name.substr(0, dot);
    const bool numbered = dot != std::string::npos && !index.empty() && index.size() <= 9 &&
                          index.find_first_not_of("0123456789") == std::string::npos;
    if (!numbered || std::stoll(index) >= samples.integer())
      samples.fail("the file holds the tensor \"" + name + "\", which is not one of samples 0.." +
                   std::to_string(samples.integer() - 1) + " (tensors are named <sample>.<input or output>)");
  }
  // A reference written for another network (another grid, other input channels) is named as
  // such, both networks described, not by the first tensor it lacks (issue 20, seventh campaign:
  // a 16^3 reference against 32^3 weights said "no tensor '0.passability'").
  {
    const auto has = [&](const std::string& name) { return ref.tensors.count(name) != 0; };
    const auto network = [](const std::vector<int>& grid, bool scale, bool passability) {
      std::string text = std::to_string(grid.size() == 3 ? grid[2] : 0) + " x " +
                         std::to_string(grid.size() == 3 ? grid[1] : 0) + " x " +
                         std::to_string(grid.size() == 3 ? grid[0] : 0) + " cells";
      text += scale ? ", with scale inputs" : ", no scale inputs";
      text += passability ? ", with passability inputs" : ", no passability inputs";
      return text;
    };
    const auto env = ref.tensors.find("0.environment");
    const std::vector<int> ref_grid = env == ref.tensors.end() ? std::vector<int>{} : env->second.shape;
    const bool ref_scale = has("0.scale"), ref_pass = has("0.passability");
    const auto& arch = sgan.architecture();
    if (env != ref.tensors.end() && (ref_grid != shape || ref_scale != (arch.scale_channels != 0) ||
                                     ref_pass != (arch.passability_channels != 0)))
      throw Error(reference_path + ": its sample 0 is for a network of " + network(ref_grid, ref_scale, ref_pass) +
                  ", but " + sgan.path() + " is a network of " +
                  network(shape, arch.scale_channels != 0, arch.passability_channels != 0) +
                  ": a reference checks the weights that wrote it (see its meta.weights)");
  }
  // An input the network is given must be finite: a NaN there was reported as the weights and
  // the reference not belonging together (sixth campaign U8). Named by tensor and element.
  const auto finite_input = [&](const std::string& name, const std::vector<int>& tensor_shape) -> const std::vector<float>& {
    const std::vector<float>& values = ref.at(name, tensor_shape).values;
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw Error(reference_path + ": " + name + "[" + std::to_string(i) + "]: is " + std::to_string(values[i]) +
                    ": a reference's inputs are finite (the network was run on them)");
    return values;
  };
  std::vector<double> errors;
  for (int k = 0; k < samples.integer(); ++k) {
    const std::string p = std::to_string(k) + ".";
    const int sc = sgan.architecture().scale_channels;
    const int pc = sgan.architecture().passability_channels;
    // The reference's own faults (a missing tensor, a NaN input) are named as the reference's,
    // before the network runs (fifteenth campaign F4: they were reported as the weights').
    const std::vector<float>& environment = finite_input(p + "environment", shape);
    const std::vector<float>& state = finite_input(p + "state", shape);
    const std::vector<float>& noise = finite_input(p + "noise", shape);
    const std::vector<float> scale = sc ? finite_input(p + "scale", {sc}) : std::vector<float>{};
    const std::vector<float> passability =
        pc ? finite_input(p + "passability", {pc, d.z(), d.y(), d.x()}) : std::vector<float>{};
    (void)ref.at(p + "output", shape);
    std::vector<float> out;
    try {
      out = sgan.forward(environment, state, noise, scale, passability);
    } catch (const Error& e) {
      // The inputs are finite (checked above): a non-finite output is the weights' overflow
      // (seventh campaign C2: it was blamed on the reference).
      throw Error(sgan.path() + ": the weights overflow a layer: on " + reference_path + "'s inputs, sample " +
                  std::to_string(k) + ": " + e.what());
    }
    const auto& want = ref.at(p + "output", shape).values;
    double worst = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double diff = std::abs(static_cast<double>(out[i]) - static_cast<double>(want[i]));
      // std::max would skip a NaN and report agreement (issue 20: an all-NaN reference "agreed").
      // forward() returns probabilities only, so a non-finite difference is the reference's fault.
      if (!std::isfinite(diff))
        throw Error(reference_path + ": " + p + "output[" + std::to_string(i) + "]: C++ gives " +
                    std::to_string(out[i]) + ", the reference " + std::to_string(want[i]) +
                    ": not a finite comparison (a reference holds finite network outputs)");
      worst = std::max(worst, diff);
    }
    errors.push_back(worst);
  }
  return errors;
}

}  // namespace miner::heuristic
